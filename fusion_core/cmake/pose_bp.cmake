# The PDR model (data/pose_bp.txt, written by train_pose) is compiled into fusion_core so the
# library stays pure (no file access at run time). Editing the file re-runs the configuration.
set(TELLTALE_POSE_BP_FILE ${CMAKE_CURRENT_SOURCE_DIR}/data/pose_bp.txt)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${TELLTALE_POSE_BP_FILE})
set(TELLTALE_POSE_BP_TEXT "")
if(EXISTS ${TELLTALE_POSE_BP_FILE})
  file(READ ${TELLTALE_POSE_BP_FILE} TELLTALE_POSE_BP_TEXT)
endif()
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/src/pose_bp_data.hpp.in
               ${CMAKE_CURRENT_BINARY_DIR}/generated/pose_bp_data.hpp @ONLY)
target_include_directories(fusion_core PRIVATE ${CMAKE_CURRENT_BINARY_DIR}/generated)

# Offline, deterministic trainer of the pose network and step-length coefficients.
add_executable(train_pose tools/train_pose.cpp)
target_link_libraries(train_pose PRIVATE fusion_core telltale_warnings)
