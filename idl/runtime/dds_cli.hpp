#pragma once
/// \file
/// The DDS flags every Telltale binary takes, written once (header-only: only the binaries that
/// parse a command line include it, and they link CLI11).

#include <CLI/CLI.hpp>

#include "dds_participant.hpp"

namespace telltale::dds {

/// The --help heading of the DDS flags in every binary; each binary's own domain (and publish
/// rate) flags join it.
inline constexpr const char* kCliGroup = "DDS";
/// The --help heading of --security-dir; a binary's other credentials (the shore's tokens) join it.
inline constexpr const char* kSecurityCliGroup = "Security";

/// --dds-profiles, --dds-participant, --dds-peer (repeatable) and --security-dir into `dds`, under
/// the headings above.
/// The domain flag stays with each binary (its help names the binary's default).
inline void add_dds_options(CLI::App& app, DdsOptions& dds) {
  app.add_option("--dds-profiles", dds.profiles_file,
                 "Fast DDS profiles XML (default: $TELLTALE_DDS_PROFILES or deploy/dds/)")
      ->group(kCliGroup);
  app.add_option("--dds-participant", dds.participant_profile, "participant profile in that file")
      ->capture_default_str()
      ->group(kCliGroup);
  app.add_option("--dds-peer", dds.peers,
                 "unicast discovery peer (IPv4), repeatable: networks without multicast "
                 "(default: $TELLTALE_DDS_PEERS, comma-separated)")
      ->group(kCliGroup);
  app.add_option("--security-dir", dds.security_dir,
                 "DDS Security: this node's folder from deploy/security/make_fleet_pki.sh "
                 "(default: unsecured)")
      ->group(kSecurityCliGroup);
}

}  // namespace telltale::dds
