#include "dds_security.hpp"

#include <openssl/sha.h>

#include <array>
#include <filesystem>
#include <fstream>

namespace telltale::dds {

namespace {

std::string required_file(const std::string& dir, const char* name) {
  const auto path = std::filesystem::path(dir) / name;
  if (!std::filesystem::exists(path))
    throw DdsError("security: " + path.string() +
                   " missing (make the folder with deploy/security/make_fleet_pki.sh)");
  return std::filesystem::absolute(path).string();
}

}  // namespace

void apply_security(const std::string& dir, eprosima::fastdds::dds::DomainParticipantQos& qos) {
  auto& props = qos.properties().properties();
  const auto uri = [&](const char* name) { return "file://" + required_file(dir, name); };
  props.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri("identity_ca.pem"));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri("cert.pem"));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri("key.pem"));
  props.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca",
                     uri("permissions_ca.pem"));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri("governance.p7s"));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions",
                     uri("permissions.p7s"));
  props.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  qos.name("telltale");
}

std::string fleet_tag(const std::string& dir, const std::string& id) {
  std::ifstream in(required_file(dir, "fleet.salt"));
  std::string salt;
  in >> salt;
  if (salt.empty()) throw DdsError("security: empty fleet.salt in " + dir);
  // Same input as the script: printf '%s:%s' "$salt" "$id" | openssl dgst -sha256.
  const std::string input = salt + ":" + id;
  std::array<unsigned char, SHA256_DIGEST_LENGTH> digest{};
  SHA256(reinterpret_cast<const unsigned char*>(input.data()), input.size(), digest.data());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string tag;
  for (std::size_t i = 0; i < 8; ++i) {
    tag += kHex[digest[i] >> 4];
    tag += kHex[digest[i] & 0xf];
  }
  return tag;
}

std::string node_partition(const std::string& dir, const std::string& id) {
  return "tt-" + fleet_tag(dir, id);
}

void use_node_partitions(DdsOptions& options, const std::string& id) {
  if (options.security_dir.empty()) return;
  options.publisher_partitions = {node_partition(options.security_dir, id)};
  options.subscriber_partitions = {kShorePartition};
}

void use_shore_partitions(DdsOptions& options) {
  if (options.security_dir.empty()) return;
  options.publisher_partitions = {kShorePartition};
  options.subscriber_partitions = {kNodePartitions};
}

}  // namespace telltale::dds
