// libFuzzer target: the vtk import parser (fuzz_import.hpp says what is checked).
#include "fuzz_import.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  telltale::fuzz::fuzz_parser(telltale::shore::import::Format::kVtk, data, size);
  return 0;
}
