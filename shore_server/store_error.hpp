#pragma once
/// \file
/// The recording store's one error: the database cannot be opened, its schema is newer than this
/// build, a statement failed or the disk is full. Thrown by the Store and by the statements it
/// and the importers run (sqlite_stmt.hpp); whatever was committed before it stays on disk.

#include <stdexcept>

namespace telltale::shore {

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace telltale::shore
