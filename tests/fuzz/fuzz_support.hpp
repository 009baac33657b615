#pragma once
/// \file
/// Helpers shared by the libFuzzer targets: a reader over the fuzzer's bytes and an invariant
/// check that aborts (libFuzzer then keeps the input as a crash file).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

namespace telltale::fuzz {

/// Stops the run with the broken invariant's text; libFuzzer saves the input that caused it.
[[noreturn]] inline void fail(const char* file, int line, const char* what) {
  std::fprintf(stderr, "INVARIANT BROKEN %s:%d: %s\n", file, line, what);
  std::abort();
}

#define FUZZ_CHECK(cond) \
  ((cond) ? static_cast<void>(0) : ::telltale::fuzz::fail(__FILE__, __LINE__, #cond))

/// Takes fixed-size values from the front of the input and hands out the rest.
class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  /// The next byte, 0 once the input is used up.
  std::uint8_t byte() {
    if (size_ == 0) return 0;
    --size_;
    return *data_++;
  }
  std::uint16_t u16() {
    const unsigned lo = byte();
    const unsigned hi = byte();
    return static_cast<std::uint16_t>(lo | (hi << 8));
  }
  std::uint64_t u64() {
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u |= static_cast<std::uint64_t>(byte()) << (8 * i);
    return u;
  }
  /// A double from 8 bytes (any bit pattern, NaN and Inf included).
  double raw_double() {
    const std::uint64_t u = u64();
    double d = 0;
    std::memcpy(&d, &u, sizeof d);
    return d;
  }
  /// Everything not yet taken.
  std::string_view rest() {
    const std::string_view s(reinterpret_cast<const char*>(data_), size_);
    data_ += size_;
    size_ = 0;
    return s;
  }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
};

/// Calls feed(offset, length) over [0, size) in pieces, as reads from a device end anywhere: whole
/// when `seed` is 0, else pieces of 1..max_piece bytes from a small generator seeded by `seed`.
template <class Feed>
void feed_in_pieces(std::size_t size, std::uint8_t seed, std::size_t max_piece, Feed feed) {
  std::uint32_t state = seed;
  std::size_t pos = 0;
  while (pos < size) {
    std::size_t n = size - pos;
    if (seed != 0) {
      state = state * 1103515245u + 12345u;
      n = std::min<std::size_t>(n, 1 + (state >> 16) % max_piece);
    }
    feed(pos, n);
    pos += n;
  }
}

/// Equal as the same number or both NaN.
inline bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace telltale::fuzz
