#pragma once
/// \file
/// Bearer-token authentication with roles (SPEC section 6). Tokens are kept only as SHA-256
/// hashes; a request presents `Authorization: Bearer TOKEN` or the `telltale_token` cookie set by
/// POST /api/v1/login.

#include <map>
#include <mutex>
#include <optional>
#include <string>

namespace telltale::shore {

enum class Role { kCoach, kAthlete, kAnalyst };

struct Principal {
  Role role = Role::kAnalyst;
  std::string boat_id;  ///< an athlete's own boat; empty otherwise
};

[[nodiscard]] const char* role_name(Role role);
/// Hex SHA-256 of a token.
[[nodiscard]] std::string token_hash(const std::string& token);
/// A fresh random token (URL-safe, 128 bits from the OS's random source).
[[nodiscard]] std::string random_token();

class TokenStore {
 public:
  void add(const std::string& token, Principal principal);
  /// The principal of a token, or nothing. Compares hashes in constant time per entry.
  [[nodiscard]] std::optional<Principal> find(const std::string& token) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, Principal> by_hash_;
};

/// The token of a request from its Authorization header or, failing that, its Cookie header.
[[nodiscard]] std::string token_from_headers(const std::string& authorization,
                                             const std::string& cookie);

}  // namespace telltale::shore
