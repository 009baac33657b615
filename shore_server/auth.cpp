#include "auth.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>

#include <array>
#include <stdexcept>

namespace telltale::shore {

const char* role_name(Role role) {
  switch (role) {
    case Role::kCoach:
      return "coach";
    case Role::kAthlete:
      return "athlete";
    case Role::kAnalyst:
      return "analyst";
  }
  return "unknown";
}

std::string token_hash(const std::string& token) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int len = 0;
  if (EVP_Digest(token.data(), token.size(), md.data(), &len, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 failed");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * len);
  for (unsigned int i = 0; i < len; ++i) {
    hex += kHex[md[i] >> 4];
    hex += kHex[md[i] & 0xF];
  }
  return hex;
}

std::string random_token() {
  std::array<unsigned char, 16> bytes{};
  if (RAND_bytes(bytes.data(), static_cast<int>(bytes.size())) != 1)
    throw std::runtime_error("no random source for a token");
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  std::string t;
  // 16 bytes -> 22 base64url characters (6 bits each, the last one carries 2 bits).
  unsigned acc = 0;
  int bits = 0;
  for (unsigned char b : bytes) {
    acc = (acc << 8) | b;
    bits += 8;
    while (bits >= 6) {
      bits -= 6;
      t += kAlphabet[(acc >> bits) & 0x3F];
    }
  }
  if (bits > 0) t += kAlphabet[(acc << (6 - bits)) & 0x3F];
  return t;
}

void TokenStore::add(const std::string& token, Principal principal) {
  std::lock_guard lock(mutex_);
  by_hash_[token_hash(token)] = std::move(principal);
}

std::optional<Principal> TokenStore::find(const std::string& token) const {
  if (token.empty() || token.size() > 256) return std::nullopt;
  const std::string h = token_hash(token);
  std::lock_guard lock(mutex_);
  std::optional<Principal> found;
  for (const auto& [hash, principal] : by_hash_) {
    if (CRYPTO_memcmp(hash.data(), h.data(), h.size()) == 0) found = principal;
  }
  return found;
}

std::string token_from_headers(const std::string& authorization, const std::string& cookie) {
  static const std::string kBearer = "Bearer ";
  if (authorization.size() > kBearer.size() && authorization.compare(0, kBearer.size(), kBearer) == 0)
    return authorization.substr(kBearer.size());
  static const std::string kName = "telltale_token=";
  std::size_t pos = 0;
  while (pos < cookie.size()) {
    while (pos < cookie.size() && (cookie[pos] == ' ' || cookie[pos] == ';')) ++pos;
    const std::size_t end = cookie.find(';', pos);
    const std::string item = cookie.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (item.compare(0, kName.size(), kName) == 0) return item.substr(kName.size());
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return "";
}

}  // namespace telltale::shore
