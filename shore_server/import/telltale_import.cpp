// telltale_import: uploads log files to a shore (POST /api/v1/imports) and waits for each import
// to finish, with a progress bar on a terminal. One line per file on stdout:
//   FILE: done, N points, sessions 4 7 (partial: REASON) | FILE: failed: ERROR
// Exit status: 0 when every file was imported, 1 when one failed, otherwise (2 or CLI11's code)
// for bad options.
#include <httplib.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Options {
  std::vector<std::string> paths;
  std::string shore = "http://127.0.0.1:8080";
  std::string token;
  std::string boat;
  std::string format;
  std::string tz;
  std::string date;
  double heel_offset = 0.0, pitch_offset = 0.0, declination = 0.0;
  bool has_declination = false;
  int timeout_s = 600;
};

/// A bar on stderr when it is a terminal; nothing otherwise.
class Progress {
 public:
  explicit Progress(std::string name) : name_(std::move(name)), tty_(isatty(STDERR_FILENO) != 0) {}
  void show(const char* phase, std::uint64_t done, std::uint64_t total) {
    if (!tty_ || total == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 30;
    const int filled = static_cast<int>(width * std::min<double>(1.0, double(done) / double(total)));
    std::fprintf(stderr, "\r%-24.24s %-9s [%s%s] %3d%% %.1f/%.1f MB", name_.c_str(), phase,
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(width - filled), ' ').c_str(),
                 static_cast<int>(100.0 * double(done) / double(total)), double(done) / 1e6,
                 double(total) / 1e6);
    std::fflush(stderr);
  }
  void clear() {
    if (tty_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  std::string name_;
  bool tty_;
  std::chrono::steady_clock::time_point last_{};
};

std::string query(const Options& o, const std::string& name) {
  httplib::Params p{{"name", name}};
  if (!o.boat.empty()) p.emplace("boat", o.boat);
  if (!o.format.empty()) p.emplace("format", o.format);
  if (!o.tz.empty()) p.emplace("tz", o.tz);
  if (!o.date.empty()) p.emplace("date", o.date);
  if (o.heel_offset != 0.0) p.emplace("heel_offset", std::to_string(o.heel_offset));
  if (o.pitch_offset != 0.0) p.emplace("pitch_offset", std::to_string(o.pitch_offset));
  if (o.has_declination) p.emplace("declination", std::to_string(o.declination));
  return "/api/v1/imports?" + httplib::detail::params_to_query_str(p);
}

std::string error_of(const httplib::Result& res) {
  if (!res) return "no answer from the shore (" + httplib::to_string(res.error()) + ")";
  const auto j = json::parse(res->body, nullptr, false);
  if (j.is_object() && j.contains("error") && j["error"].is_string())
    return "HTTP " + std::to_string(res->status) + ": " + j["error"].get<std::string>();
  return "HTTP " + std::to_string(res->status);
}

/// Uploads one file and waits for its import; true when it was imported.
bool import_file(httplib::Client& client, const Options& o, const fs::path& file) {
  const std::string name = file.filename().string();
  std::ifstream in(file, std::ios::binary);
  std::error_code ec;
  const std::uint64_t size = fs::file_size(file, ec);
  if (!in || ec) {
    std::printf("%s: failed: cannot read it\n", file.c_str());
    return false;
  }
  Progress bar(name);
  const httplib::Headers auth{{"Authorization", "Bearer " + o.token}};
  std::vector<char> buf(1 << 16);
  auto res = client.Post(
      query(o, name), auth, static_cast<std::size_t>(size),
      [&](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        in.seekg(static_cast<std::streamoff>(offset));
        in.read(buf.data(), static_cast<std::streamsize>(std::min(length, buf.size())));
        const auto n = static_cast<std::size_t>(in.gcount());
        if (n == 0) return false;
        bar.show("uploading", offset + n, size);
        return sink.write(buf.data(), n);
      },
      "application/octet-stream");
  if (!res || res->status != 202) {
    bar.clear();
    std::printf("%s: failed: %s\n", file.c_str(), error_of(res).c_str());
    return false;
  }
  const auto id = json::parse(res->body, nullptr, false).value("id", std::int64_t{0});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(o.timeout_s);
  json r;
  for (;;) {
    auto st = client.Get("/api/v1/imports/" + std::to_string(id), auth);
    if (!st || st->status != 200) {
      bar.clear();
      std::printf("%s: failed: %s\n", file.c_str(), error_of(st).c_str());
      return false;
    }
    r = json::parse(st->body, nullptr, false);
    if (!r.is_object()) r = json::object();
    if (r.value("state", "") != "running") break;
    bar.show("importing", r.value("bytes_read", std::uint64_t{0}), size);
    if (std::chrono::steady_clock::now() > deadline) {
      bar.clear();
      std::printf("%s: failed: still running after %d s (import %lld)\n", file.c_str(),
                  o.timeout_s, static_cast<long long>(id));
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  bar.clear();
  if (r.value("state", "") != "done") {
    std::printf("%s: failed: %s\n", file.c_str(),
                r["error"].is_string() ? r["error"].get<std::string>().c_str() : "unknown error");
    return false;
  }
  std::string sessions;
  for (const auto& s : r["sessions"]) sessions += " " + s.dump();
  std::printf("%s: done, %s, %llu points, sessions%s%s%s%s\n", file.c_str(),
              r.value("format", std::string("?")).c_str(),
              static_cast<unsigned long long>(r.value("points", std::uint64_t{0})),
              sessions.empty() ? " none" : sessions.c_str(),
              r["duplicate_of"].is_number() ? " (already imported)" : "",
              r["partial"].is_string() ? " (partial: " : "",
              r["partial"].is_string() ? (r["partial"].get<std::string>() + ")").c_str() : "");
  std::fflush(stdout);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "Uploads log files (Vakaros CSV/VKX, Velocitek VTK, NMEA 0183, GPX) to a Telltale shore "
      "as sessions of one boat; one line per file on stdout, a progress bar on a terminal"};
  app.set_config("--config", "", "read options from this file (INI/TOML: key = value)");
  app.add_option("paths", o.paths, "files, or folders whose files are all uploaded")
      ->required()
      ->check(CLI::ExistingPath);
  // --help: where the files go, what they are, what to correct in them.
  const std::string shore_heading = "Shore";
  app.add_option("--shore", o.shore, "the shore's URL")
      ->capture_default_str()
      ->group(shore_heading);
  app.add_option("--token", o.token, "coach or analyst token (default: $TELLTALE_TOKEN)")
      ->group(shore_heading);
  app.add_option("--timeout-s", o.timeout_s, "give up waiting for one import after this long")
      ->check(CLI::Range(1, 86400))
      ->capture_default_str()
      ->group(shore_heading);

  const std::string files_heading = "Files";
  app.add_option("--boat", o.boat,
                 "the boat the files belong to (without it: the device's serial where a file "
                 "names one, Velocitek VTK)")
      ->group(files_heading);
  app.add_option("--format", o.format, "force the format instead of reading it from the content")
      ->check(CLI::IsMember({"vakaros_csv", "vkx", "vtk", "nmea", "gpx"}))
      ->group(files_heading);
  app.add_option("--tz", o.tz,
                 "time zone of local times without an offset (Europe/Madrid, +01:00, UTC)")
      ->group(files_heading);
  app.add_option("--date", o.date, "UTC date (YYYY-MM-DD) of NMEA logs that state none")
      ->group(files_heading);

  const std::string corrections_heading = "Corrections";
  app.add_option("--heel-offset", o.heel_offset, "degrees subtracted from every heel")
      ->check(CLI::Range(-45.0, 45.0))
      ->group(corrections_heading);
  app.add_option("--pitch-offset", o.pitch_offset, "degrees subtracted from every pitch")
      ->check(CLI::Range(-45.0, 45.0))
      ->group(corrections_heading);
  auto* decl = app.add_option("--declination", o.declination,
                              "east positive, for magnetic headings when a file states none")
                   ->check(CLI::Range(-90.0, 90.0))
                   ->group(corrections_heading);
  CLI11_PARSE(app, argc, argv);
  o.has_declination = decl->count() > 0;
  if (o.token.empty())
    if (const char* t = std::getenv("TELLTALE_TOKEN")) o.token = t;
  if (o.token.empty()) {
    std::fprintf(stderr, "telltale_import: give --token or set TELLTALE_TOKEN\n");
    return 2;
  }
  std::vector<fs::path> files;
  for (const auto& p : o.paths) {
    if (fs::is_directory(p)) {
      std::vector<fs::path> in_dir;
      for (const auto& e : fs::recursive_directory_iterator(p))
        if (e.is_regular_file()) in_dir.push_back(e.path());
      std::sort(in_dir.begin(), in_dir.end());
      files.insert(files.end(), in_dir.begin(), in_dir.end());
    } else {
      files.emplace_back(p);
    }
  }
  httplib::Client client(o.shore);
  if (!client.is_valid()) {
    std::fprintf(stderr, "telltale_import: --shore %s is not an http:// URL\n", o.shore.c_str());
    return 2;
  }
  client.set_connection_timeout(5);
  client.set_read_timeout(60);
  client.set_write_timeout(60);
  int failed = 0;
  for (const auto& f : files)
    if (!import_file(client, o, f)) ++failed;
  if (files.size() > 1)
    std::printf("%zu files, %zu imported, %d failed\n", files.size(), files.size() - static_cast<std::size_t>(failed),
                failed);
  return failed == 0 ? 0 : 1;
}
