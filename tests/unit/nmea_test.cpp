// NMEA 0183 heading input: parser (incl. hostile input), line assembler, and the serial and UDP
// readers over a real pseudo-terminal and loopback UDP.
#include "nmea.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <random>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace telltale::sensors {
namespace {

/// "$" + body + "*hh" with the checksum computed here, independently of the parser.
std::string sentence(const std::string& body) {
  unsigned x = 0;
  for (char c : body) x ^= static_cast<unsigned char>(c);
  char cs[4];
  std::snprintf(cs, sizeof cs, "%02X", x);
  return "$" + body + "*" + cs;
}

NmeaStatus status_of(const std::string& line, NmeaParseOptions o = {}) {
  return parse_nmea_heading(line, o).status;
}

// ------------------------------------------------------------------------- parser

TEST(NmeaParse, HdtFromAnyTalker) {
  for (const char* talker : {"HE", "HC", "GP", "GN", "II", "IN", "YZ"}) {
    const auto r = parse_nmea_heading(sentence(std::string(talker) + "HDT,274.07,T") + "\r\n");
    ASSERT_EQ(r.status, NmeaStatus::kOk) << talker;
    EXPECT_STREQ(r.heading.talker.data(), talker);
    EXPECT_EQ(r.heading.sentence, NmeaSentence::kHdt);
    EXPECT_DOUBLE_EQ(r.heading.true_deg, 274.07);
    EXPECT_TRUE(std::isnan(r.heading.magnetic_deg));
    EXPECT_TRUE(r.heading.had_checksum);
  }
}

TEST(NmeaParse, HdgAppliesDeviationAndVariation) {
  // 98.3 sensor, deviation 0.5 E -> magnetic 98.8; variation 12.6 W -> true 86.2
  auto r = parse_nmea_heading(sentence("HCHDG,98.3,0.5,E,12.6,W"));
  ASSERT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_NEAR(r.heading.magnetic_deg, 98.8, 1e-9);
  EXPECT_NEAR(r.heading.true_deg, 86.2, 1e-9);
  EXPECT_NEAR(r.heading.deviation_deg, 0.5, 1e-12);
  EXPECT_NEAR(r.heading.variation_deg, -12.6, 1e-12);
  // wrapping through north both ways
  r = parse_nmea_heading(sentence("HCHDG,359.0,2.0,E,3.0,E"));
  ASSERT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_NEAR(r.heading.magnetic_deg, 1.0, 1e-9);
  EXPECT_NEAR(r.heading.true_deg, 4.0, 1e-9);
  r = parse_nmea_heading(sentence("HCHDG,1.0,,,2.5,W"));
  ASSERT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_NEAR(r.heading.true_deg, 358.5, 1e-9);
  // no variation: magnetic only, true heading unknown (never guessed)
  r = parse_nmea_heading(sentence("HCHDG,45.0,1.0,W,,"));
  ASSERT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_NEAR(r.heading.magnetic_deg, 44.0, 1e-9);
  EXPECT_TRUE(std::isnan(r.heading.true_deg));
  EXPECT_TRUE(std::isnan(r.heading.variation_deg));
}

TEST(NmeaParse, HdmIsMagnetic) {
  const auto r = parse_nmea_heading(sentence("HCHDM,123.4,M"));
  ASSERT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_EQ(r.heading.sentence, NmeaSentence::kHdm);
  EXPECT_DOUBLE_EQ(r.heading.magnetic_deg, 123.4);
  EXPECT_TRUE(std::isnan(r.heading.true_deg));
}

TEST(NmeaParse, ChecksumVerifiedMissingOnlyWhenAllowed) {
  std::string good = sentence("HEHDT,10.0,T");
  EXPECT_EQ(status_of(good), NmeaStatus::kOk);
  int with_letters = 0;
  for (int deg = 0; deg < 40; ++deg) {  // hex digits in lower case are accepted
    std::string lower = sentence("HEHDT," + std::to_string(deg) + ".0,T");
    for (std::size_t i = lower.find('*') + 1; i < lower.size(); ++i) {
      with_letters += std::isalpha(static_cast<unsigned char>(lower[i])) ? 1 : 0;
      lower[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(lower[i])));
    }
    EXPECT_EQ(status_of(lower), NmeaStatus::kOk) << lower;
  }
  EXPECT_GT(with_letters, 0);
  std::string bad = good;
  bad[8] = '1';  // "10.0" -> "11.0", checksum no longer matches
  EXPECT_EQ(status_of(bad), NmeaStatus::kBadChecksum);
  EXPECT_EQ(status_of("$HEHDT,10.0,T*"), NmeaStatus::kBadChecksum);
  EXPECT_EQ(status_of("$HEHDT,10.0,T*G1"), NmeaStatus::kBadChecksum);
  EXPECT_EQ(status_of("$HEHDT,10.0,T*123"), NmeaStatus::kBadChecksum);
  EXPECT_EQ(status_of("$HEHDT,10.0,T"), NmeaStatus::kMissingChecksum);
  NmeaParseOptions lax;
  lax.accept_missing_checksum = true;
  const auto r = parse_nmea_heading("$HEHDT,10.0,T", lax);
  EXPECT_EQ(r.status, NmeaStatus::kOk);
  EXPECT_FALSE(r.heading.had_checksum);
}

TEST(NmeaParse, HostileFieldsAreMalformedNeverNumbers) {
  for (const char* f : {"nan", "NaN", "inf", "-5.0", "+5", "1e2", "361.0", "", " 5", "5 ", "1.2.3",
                        "0x10", "12,5", "99999999999999999999"}) {
    EXPECT_EQ(status_of(sentence(std::string("HEHDT,") + f + ",T")), NmeaStatus::kMalformed) << f;
  }
  EXPECT_EQ(status_of(sentence("HEHDT,360.0,T")), NmeaStatus::kOk);  // reads as 0
  EXPECT_EQ(parse_nmea_heading(sentence("HEHDT,360.0,T")).heading.true_deg, 0.0);
  EXPECT_EQ(status_of(sentence("HEHDT,10.0,M")), NmeaStatus::kMalformed);  // wrong unit letter
  EXPECT_EQ(status_of(sentence("HCHDG,10.0,1.0,N,,")), NmeaStatus::kMalformed);
  EXPECT_EQ(status_of(sentence("HCHDG,10.0,1.0,E,2.0")), NmeaStatus::kMalformed);  // 4 fields
  EXPECT_EQ(status_of(sentence("HCHDG,10.0,200,E,,")), NmeaStatus::kMalformed);
  EXPECT_EQ(status_of(sentence("HEHDT")), NmeaStatus::kMalformed);
  EXPECT_EQ(status_of(sentence("HEHDTX,1.0,T")), NmeaStatus::kMalformed);
  std::string ctrl = "HEHDT,1\x01.0,T";
  EXPECT_EQ(status_of(sentence(ctrl)), NmeaStatus::kMalformed);
}

TEST(NmeaParse, TruncatedUnsupportedAndNotNmea) {
  EXPECT_EQ(status_of("$HEHD"), NmeaStatus::kNotNmea);
  EXPECT_EQ(status_of(""), NmeaStatus::kNotNmea);
  EXPECT_EQ(status_of("HEHDT,1.0,T*00"), NmeaStatus::kNotNmea);
  EXPECT_EQ(status_of("$he hdt,1.0,T"), NmeaStatus::kNotNmea);
  EXPECT_EQ(status_of(sentence("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")),
            NmeaStatus::kUnsupported);
  const std::string full = sentence("HEHDT,274.07,T");
  for (std::size_t cut = 0; cut < full.size(); ++cut) {  // every prefix: never kOk, never a crash
    EXPECT_NE(status_of(full.substr(0, cut)), NmeaStatus::kOk) << cut;
  }
  EXPECT_EQ(status_of(std::string(10000, 'A')), NmeaStatus::kTooLong);
  EXPECT_EQ(status_of("$HEHDT," + std::string(10000, '1') + ",T"), NmeaStatus::kTooLong);
}

TEST(NmeaParse, RandomBinaryNeverCrashesNorParses) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 20000; ++k) {
    std::string s(static_cast<std::size_t>(byte(rng) % 100), '\0');
    for (auto& c : s) c = static_cast<char>(byte(rng));
    if (!s.empty() && k % 2 == 0) s[0] = '$';
    EXPECT_NE(status_of(s), NmeaStatus::kOk);
  }
}

// ------------------------------------------------------------------------- assembler

TEST(NmeaAssembler, EverySplitPointAndLineEndingGivesTheSameLines) {
  const std::string a = sentence("HEHDT,1.5,T");
  const std::string b = sentence("HCHDG,98.3,0.5,E,12.6,W");
  const std::string stream =
      "junk" + a + "\r\n" + b + "\n\r\n" + a + "\r" + std::string("\x00\xff", 2) + b + "\n";
  for (std::size_t split = 0; split <= stream.size(); ++split) {
    NmeaLineAssembler asmb;
    std::vector<std::string> lines;
    const auto cb = [&](std::string_view l) { lines.emplace_back(l); };
    asmb.feed(stream.data(), split, cb);
    asmb.feed(stream.data() + split, stream.size() - split, cb);
    ASSERT_EQ(lines.size(), 4u) << split;
    EXPECT_EQ(lines[0], a);
    EXPECT_EQ(lines[1], b);
    EXPECT_EQ(lines[2], a);
    EXPECT_EQ(lines[3], b);
    EXPECT_EQ(asmb.stats().garbage_bytes, 6u);
  }
}

TEST(NmeaAssembler, OverlongLinesAreDroppedWholeAndTheNextOneSurvives) {
  NmeaLineAssembler asmb;
  std::vector<std::string> lines;
  const auto cb = [&](std::string_view l) { lines.emplace_back(l); };
  const std::string big = "$HEHDT," + std::string(10 * 1024, '7') + "\r\n";
  const std::string good = sentence("HEHDT,2.0,T") + "\r\n";
  for (std::size_t i = 0; i < big.size(); i += 333) {
    asmb.feed(big.data() + i, std::min<std::size_t>(333, big.size() - i), cb);
  }
  asmb.feed(good.data(), good.size(), cb);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(parse_nmea_heading(lines[0]).status, NmeaStatus::kOk);
  EXPECT_EQ(asmb.stats().overlong, 1u);
  // a sentence cut by the next '$' is counted, not glued
  const std::string cut = "$HEHDT,12" + good;
  asmb.feed(cut.data(), cut.size(), cb);
  EXPECT_EQ(asmb.stats().truncated, 1u);
  EXPECT_EQ(lines.size(), 2u);
}

// ------------------------------------------------------------------------- readers

struct Collected {
  std::mutex m;
  std::vector<NmeaHeading> h;
  std::size_t size() {
    std::lock_guard<std::mutex> g(m);
    return h.size();
  }
};

bool wait_for(Collected& c, std::size_t n, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (c.size() >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return c.size() >= n;
}

TEST(NmeaSerial, ReadsAPseudoTerminalInPiecesAndStopsCleanly) {
  // Given a pseudo-terminal whose slave side the reader opens as its serial device
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string slave = ::ptsname(master);
  NmeaSerialReader reader(slave, 38400);
  Collected got;
  std::thread th([&] {
    reader.run([&](const NmeaHeading& h, NmeaClock::time_point) {
      std::lock_guard<std::mutex> g(got.m);
      got.h.push_back(h);
    });
  });
  // When sentences, a bad checksum and garbage arrive in odd-sized writes
  std::string stream;
  for (int i = 0; i < 20; ++i) {
    stream += sentence("HEHDT," + std::to_string(i) + ".5,T") + "\r\n";
    if (i == 7) stream += "$HEHDT,7.5,T*00\r\n\x01\x02garbage";
  }
  for (std::size_t i = 0; i < stream.size(); i += 7) {
    const auto n = std::min<std::size_t>(7, stream.size() - i);
    ASSERT_EQ(::write(master, stream.data() + i, n), static_cast<ssize_t>(n));
  }
  // Then every good heading comes through in order and the bad one is counted
  EXPECT_TRUE(wait_for(got, 20, std::chrono::seconds(5)));
  const auto t0 = std::chrono::steady_clock::now();
  reader.stop();
  th.join();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  ASSERT_EQ(got.h.size(), 20u);
  for (int i = 0; i < 20; ++i)
    EXPECT_DOUBLE_EQ(got.h[static_cast<std::size_t>(i)].true_deg, i + 0.5);
  EXPECT_EQ(reader.stats().bad_checksum, 1u);
  EXPECT_EQ(reader.stats().accepted, 20u);
  EXPECT_GT(reader.stats().garbage_bytes, 0u);
  ::close(master);
}

TEST(NmeaSerial, SetupErrorsThrow) {
  EXPECT_THROW(NmeaSerialReader("/nonexistent/tty", 4800), std::system_error);
  EXPECT_THROW(NmeaSerialReader("/dev/null", 4800), std::system_error);  // not a tty
  EXPECT_THROW(NmeaSerialReader("/dev/null", 1234), std::invalid_argument);
  EXPECT_THROW(NmeaUdpReader("not-an-address", 0), std::invalid_argument);
}

TEST(NmeaUdp, ReadsLoopbackDatagramsOnAPortPickedByTheOs) {
  NmeaUdpReader reader("127.0.0.1", 0);
  ASSERT_NE(reader.port(), 0);
  const int tx = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(tx, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(reader.port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const auto send = [&](const std::string& d) {
    ASSERT_EQ(
        ::sendto(tx, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
        static_cast<ssize_t>(d.size()));
  };
  // two sentences in one datagram, one without a line ending, garbage, a 10 kB datagram
  send(sentence("HEHDT,10.0,T") + "\r\n" + sentence("HCHDM,20.0,M") + "\r\n");
  send(sentence("GPHDT,30.0,T"));
  send(std::string("\xde\xad\xbe\xef", 4));
  send("$HEHDT," + std::string(10000, '5') + ",T\r\n");
  send(sentence("IIHDG,40.0,,,1.0,E") + "\r\n");
  Collected got;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (got.h.size() < 4 && std::chrono::steady_clock::now() < end) {
    ASSERT_TRUE(reader.poll_once(
        100, [&](const NmeaHeading& h, NmeaClock::time_point) { got.h.push_back(h); }));
  }
  ASSERT_EQ(got.h.size(), 4u);
  EXPECT_DOUBLE_EQ(got.h[0].true_deg, 10.0);
  EXPECT_DOUBLE_EQ(got.h[1].magnetic_deg, 20.0);
  EXPECT_DOUBLE_EQ(got.h[2].true_deg, 30.0);
  EXPECT_DOUBLE_EQ(got.h[3].true_deg, 41.0);
  EXPECT_EQ(reader.stats().malformed, 1u);  // the over-long one
  EXPECT_EQ(reader.stats().garbage_bytes, 4u);
  reader.stop();
  EXPECT_FALSE(reader.poll_once(100, {}));
  ::close(tx);
}

}  // namespace
}  // namespace telltale::sensors
