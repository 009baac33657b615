#include "csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace telltale::io {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

void split(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      cells.push_back(trim(line.substr(start)));
      return;
    }
    cells.push_back(trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

bool is_nan_word(std::string_view s) {
  return s.empty() || s == "nan" || s == "NaN" || s == "NAN" || s == "-nan";
}

}  // namespace

CsvReader::CsvReader(std::string path, std::vector<CsvColumn> columns,
                     std::optional<std::string> time_column, TimeOrder order)
    : path_(std::move(path)), columns_(std::move(columns)), in_(path_), order_(order) {
  if (!in_) throw CsvError(path_ + ":0:0: cannot open file");
  if (!std::getline(in_, buffer_)) throw CsvError(path_ + ":1:0: empty file (no header line)");
  line_ = 1;
  // A UTF-8 byte-order mark before the first name is tolerated.
  if (buffer_.size() >= 3 && buffer_.compare(0, 3, "\xEF\xBB\xBF") == 0) buffer_.erase(0, 3);
  split(buffer_, cells_);
  header_.assign(cells_.begin(), cells_.end());
  source_index_.assign(columns_.size(), -1);
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    const auto it = std::find(header_.begin(), header_.end(), columns_[i].name);
    if (it != header_.end()) {
      source_index_[i] = static_cast<int>(it - header_.begin());
    } else if (columns_[i].required) {
      throw CsvError(path_ + ":1:0: missing column '" + columns_[i].name + "'");
    }
    if (time_column && columns_[i].name == *time_column) time_index_ = static_cast<int>(i);
  }
}

bool CsvReader::has_column(std::string_view name) const {
  for (std::size_t i = 0; i < columns_.size(); ++i)
    if (columns_[i].name == name) return source_index_[i] >= 0;
  return std::find(header_.begin(), header_.end(), name) != header_.end();
}

void CsvReader::fail(std::size_t column_1based, const std::string& what) const {
  throw CsvError(path_ + ":" + std::to_string(line_) + ":" + std::to_string(column_1based) + ": " +
                 what);
}

bool CsvReader::next(std::vector<double>& values) {
  for (;;) {
    if (!std::getline(in_, buffer_)) {
      if (in_.bad()) fail(0, "read error");
      return false;
    }
    ++line_;
    if (!trim(buffer_).empty()) break;  // blank lines (e.g. a trailing newline) are skipped
  }
  split(buffer_, cells_);
  if (cells_.size() != header_.size())
    fail(std::min(cells_.size(), header_.size()) + 1, "expected " + std::to_string(header_.size()) +
                                                          " fields, found " +
                                                          std::to_string(cells_.size()));
  values.resize(columns_.size());
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    const int src = source_index_[i];
    if (src < 0) {
      values[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const std::string_view cell = cells_[static_cast<std::size_t>(src)];
    const auto column = static_cast<std::size_t>(src) + 1;
    if (columns_[i].allow_missing && is_nan_word(cell)) {
      values[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (cell.empty()) fail(column, "empty value in column '" + columns_[i].name + "'");
    double v = 0.0;
    const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
    if (ec != std::errc() || end != cell.data() + cell.size())
      fail(column,
           "not a number in column '" + columns_[i].name + "': '" + std::string(cell) + "'");
    if (!std::isfinite(v)) fail(column, "non-finite value in column '" + columns_[i].name + "'");
    values[i] = v;
  }
  if (time_index_ >= 0) {
    const double t = values[static_cast<std::size_t>(time_index_)];
    const auto column =
        static_cast<std::size_t>(source_index_[static_cast<std::size_t>(time_index_)]) + 1;
    if (!std::isfinite(t)) fail(column, "missing time");
    if (have_time_ && t == last_time_ && order_ == TimeOrder::kNonDecreasing) {
      ++repeated_times_;
    } else if (have_time_ && !(t > last_time_)) {
      fail(column, std::string(order_ == TimeOrder::kNonDecreasing ? "time goes backwards"
                                                                   : "time not increasing") +
                       " (" + std::to_string(t) + " after " + std::to_string(last_time_) + ")");
    }
    last_time_ = t;
    have_time_ = true;
  }
  return true;
}

const std::vector<double>& CsvTable::col(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return columns[i];
  throw std::out_of_range("no column " + std::string(name));
}

CsvTable read_csv(const std::string& path, const std::vector<CsvColumn>& columns,
                  std::optional<std::string> time_column) {
  CsvReader reader(path, columns, std::move(time_column));
  CsvTable table;
  for (const auto& c : columns) table.names.push_back(c.name);
  table.columns.resize(columns.size());
  std::vector<double> row;
  while (reader.next(row))
    for (std::size_t i = 0; i < row.size(); ++i) table.columns[i].push_back(row[i]);
  if (table.rows() == 0) throw CsvError(path + ":2:0: no data rows");
  return table;
}

CsvWriter::CsvWriter(std::string path, const std::vector<std::string>& header)
    : path_(std::move(path)), out_(path_) {
  if (!out_) throw CsvError(path_ + ":0:0: cannot create file");
  for (std::size_t i = 0; i < header.size(); ++i) out_ << (i ? "," : "") << header[i];
  out_ << '\n';
}

void CsvWriter::row(const std::vector<double>& values) {
  line_.clear();
  char num[32];
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line_ += ',';
    if (std::isnan(values[i])) {
      line_ += "nan";
    } else {
      const int n = std::snprintf(num, sizeof num, "%.9g", values[i]);
      line_.append(num, static_cast<std::size_t>(n));
    }
  }
  line_ += '\n';
  out_ << line_;
}

void CsvWriter::close() {
  out_.flush();
  if (!out_) throw CsvError(path_ + ":0:0: write failed");
  out_.close();
}

}  // namespace telltale::io
