#pragma once
/// \file
/// Column-named CSV reading and writing for the file formats of SPEC section 6.
///
/// Not part of the pure fusion core: it touches files. Every error names the file, the line and
/// the column, in one line, so `fusion_cli` can print it and exit with status 2.

#include <cstddef>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace telltale::io {

/// Bad input: the message is one line, "FILE:LINE:COLUMN: what".
class CsvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How a column may be filled.
struct CsvColumn {
  std::string name;
  bool required = true;        ///< missing from the header -> error
  bool allow_missing = false;  ///< empty cell or "nan" -> NaN instead of an error
};

/// What the time column may do from one row to the next.
enum class TimeOrder {
  kIncreasing,     ///< strictly increasing: a repeated time stamp is an error
  kNonDecreasing,  ///< a repeated time stamp is returned (and counted); backwards is an error
};

/// Streams the rows of a CSV file with a header line, picking columns by name in any order.
/// Extra columns are ignored. Numbers are parsed strictly (no trailing text); NaN/Inf are errors
/// unless the column allows missing values (then an empty cell or "nan" reads as NaN).
/// If `time_column` is set, its values must be finite and follow `order`; time going backwards
/// is always an error naming the file, line and column.
class CsvReader {
 public:
  /// Opens the file and reads the header. Throws CsvError (missing file, empty file, missing
  /// required column).
  CsvReader(std::string path, std::vector<CsvColumn> columns,
            std::optional<std::string> time_column = std::nullopt,
            TimeOrder order = TimeOrder::kIncreasing);

  /// Reads the next data row into `values` (one entry per requested column, in request order;
  /// an absent optional column reads as NaN). Returns false at end of file. Throws CsvError.
  [[nodiscard]] bool next(std::vector<double>& values);

  /// True when the (optional) column was present in the header.
  [[nodiscard]] bool has_column(std::string_view name) const;
  [[nodiscard]] const std::string& path() const { return path_; }
  /// 1-based line number of the row last returned.
  [[nodiscard]] std::size_t line() const { return line_; }
  /// Rows returned so far whose time equals the previous row's (TimeOrder::kNonDecreasing).
  [[nodiscard]] std::size_t repeated_times() const { return repeated_times_; }

 private:
  [[noreturn]] void fail(std::size_t column_1based, const std::string& what) const;

  std::string path_;
  std::vector<CsvColumn> columns_;
  std::ifstream in_;
  std::vector<int> source_index_;  ///< per requested column: index in the file, -1 if absent
  std::vector<std::string> header_;
  int time_index_ = -1;  ///< index into columns_ of the time column
  TimeOrder order_ = TimeOrder::kIncreasing;
  std::size_t repeated_times_ = 0;
  double last_time_ = 0.0;
  bool have_time_ = false;
  std::size_t line_ = 0;
  std::string buffer_;
  std::vector<std::string_view> cells_;
};

/// Reads a whole file into columns (convenience for offline tools).
struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  ///< columns[i] holds every row of names[i]
  [[nodiscard]] std::size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  [[nodiscard]] const std::vector<double>& col(std::string_view name) const;
};
[[nodiscard]] CsvTable read_csv(const std::string& path, const std::vector<CsvColumn>& columns,
                                std::optional<std::string> time_column = std::nullopt);

/// Writes a CSV with a header; numbers with enough digits to round-trip the value they stand for
/// (up to 9 significant digits), NaN written as "nan".
class CsvWriter {
 public:
  /// Throws CsvError if the file cannot be created.
  CsvWriter(std::string path, const std::vector<std::string>& header);
  void row(const std::vector<double>& values);
  /// Flushes and reports a write failure (disk full) as CsvError.
  void close();

 private:
  std::string path_;
  std::ofstream out_;
  std::string line_;
};

}  // namespace telltale::io
