#pragma once
/// \file
/// Secured mode (DDS Security with Fast DDS's builtin plugins): the participant properties for a
/// node folder made by deploy/security/make_fleet_pki.sh, and the per-node partitions that carry
/// the authorisation "a boat publishes only its own data" (deploy/security/README.md).
///
/// A node folder holds identity_ca.pem, cert.pem, key.pem, permissions_ca.pem, governance.p7s,
/// permissions.p7s and fleet.salt. Partition and certificate names are tt-<tag> / node-<tag> with
/// tag(id) = the first 16 hex digits of SHA-256(salt ":" id): the handshake sends the certificate
/// and the permissions document in clear, and neither may name the boat.

#include <string>

#include "dds_participant.hpp"

namespace telltale::dds {

/// The shore's partition (alarm rules, events, receipts); boats and wearables read it.
inline constexpr const char* kShorePartition = "tt-shore";
/// Every node partition; the shore reads it.
inline constexpr const char* kNodePartitions = "tt-*";

/// Adds the PKI-DH, Access-Permissions and AES-GCM-GMAC properties for the node folder `dir` and
/// replaces the participant name by an opaque one (the participant announcement stays in clear).
/// Throws DdsError when a file is missing.
void apply_security(const std::string& dir, eprosima::fastdds::dds::DomainParticipantQos& qos);

/// tag(id) with the fleet salt of the node folder `dir`. Throws DdsError without a salt.
[[nodiscard]] std::string fleet_tag(const std::string& dir, const std::string& id);
/// "tt-" + fleet_tag(dir, id): the only partition node `id` may publish in.
[[nodiscard]] std::string node_partition(const std::string& dir, const std::string& id);

/// When options are secured: a boat or wearable publishes in its own partition and reads the
/// shore's. Unsecured options are left alone (default partition, as before).
void use_node_partitions(DdsOptions& options, const std::string& id);
/// When options are secured: the shore publishes in its partition and reads every node's.
void use_shore_partitions(DdsOptions& options);

}  // namespace telltale::dds
