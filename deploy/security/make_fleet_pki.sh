#!/usr/bin/env bash
# Creates (or completes) a Telltale fleet PKI for DDS Security with openssl only, ECDSA P-256:
#
#   OUTDIR/ca/                  identity CA and permissions CA (keys 0600, never leave this host)
#   OUTDIR/fleet.salt           random fleet secret; partitions and node names are hashes of it
#   OUTDIR/<node>/              everything one node needs, given to it as --security-dir:
#       identity_ca.pem permissions_ca.pem governance.p7s fleet.salt
#       cert.pem key.pem (0600) permissions.p7s (and the unsigned .xml for reading)
#
# <node> is a boat id, a wearable's athlete id (--wearable ID) or "shore". Idempotent: existing
# CAs, salt and node files are kept; only missing nodes are created. To renew a node, delete its
# folder and run again.
#
# Authorisation (see deploy/security/README.md): boat/wearable X may publish only in partition
# tt-<tag(X)> and subscribe only to the shore's partition tt-shore; the shore publishes in
# tt-shore and subscribes to tt-*. tag(X) = first 16 hex digits of SHA-256(salt ":" X). Node
# certificates are named CN=node-<tag(X)> so neither the certificate nor the permissions document,
# both sent in clear during the handshake, name the boat.
#
# Usage: make_fleet_pki.sh [--wearable ID]... [--days N] [--start YYYYMMDDHHMMSSZ
#                          --end YYYYMMDDHHMMSSZ] OUTDIR BOAT_ID...
#   --days N       validity of new node certificates and permissions (default 825)
#   --start/--end  explicit validity of new node certificates (e.g. in the past: an EXPIRED one)
set -euo pipefail

usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit "${1:-2}"; }

days=825
start=""
end=""
wearables=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --wearable) wearables+=("$2"); shift 2 ;;
    --days) days="$2"; shift 2 ;;
    --start) start="$2"; shift 2 ;;
    --end) end="$2"; shift 2 ;;
    -h|--help) usage 0 ;;
    --) shift; break ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) break ;;
  esac
done
[[ $# -ge 1 ]] || usage
out="$1"; shift
boats=("$@")
if [[ -n "$start" && -z "$end" || -z "$start" && -n "$end" ]]; then
  echo "--start and --end go together" >&2; exit 2
fi
for id in "${boats[@]}" "${wearables[@]}"; do
  [[ "$id" =~ ^[A-Za-z0-9_-]{1,32}$ ]] || { echo "bad node id '$id' ([A-Za-z0-9_-]{1,32})" >&2; exit 2; }
  [[ "$id" != shore && "$id" != ca ]] || { echo "'$id' is reserved" >&2; exit 2; }
done

command -v openssl >/dev/null || { echo "openssl is needed" >&2; exit 1; }
umask 077
mkdir -p "$out/ca"
ca="$out/ca"
subject_o="/O=Telltale fleet"

# One CA: self-signed, 10 years, with an `openssl ca` database so node certificates can be given
# an explicit validity window.
make_ca() {
  local name="$1" cn="$2"
  [[ -f "$ca/$name.pem" ]] && return
  openssl ecparam -name prime256v1 -genkey -noout -out "$ca/$name.key"
  openssl req -new -x509 -sha256 -days 3650 -key "$ca/$name.key" -out "$ca/$name.pem" \
    -subj "$subject_o/CN=$cn" -addext basicConstraints=critical,CA:TRUE \
    -addext keyUsage=critical,keyCertSign,cRLSign,digitalSignature
  mkdir -p "$ca/$name.db"
  : >"$ca/$name.db/index.txt"
  openssl rand -hex 16 >"$ca/$name.db/serial"
  cat >"$ca/$name.cnf" <<CNF
[ca]
default_ca = this
[this]
dir = $ca/$name.db
database = \$dir/index.txt
serial = \$dir/serial
new_certs_dir = \$dir
certificate = $ca/$name.pem
private_key = $ca/$name.key
default_md = sha256
policy = any
unique_subject = no
copy_extensions = none
x509_extensions = node_ext
[any]
organizationName = supplied
commonName = supplied
[node_ext]
basicConstraints = critical,CA:FALSE
keyUsage = critical,digitalSignature,keyAgreement
CNF
}
make_ca identity_ca "Telltale identity CA"
make_ca permissions_ca "Telltale permissions CA"
[[ -f "$out/fleet.salt" ]] || openssl rand -hex 32 >"$out/fleet.salt"
salt="$(cat "$out/fleet.salt")"

tag() { printf '%s:%s' "$salt" "$1" | openssl dgst -sha256 -r | cut -c1-16; }
sign() {  # S/MIME clear-signed with the permissions CA, as DDS Security expects
  openssl smime -sign -text -in "$1" -out "$2" -signer "$ca/permissions_ca.pem" \
    -inkey "$ca/permissions_ca.key"
}

if [[ ! -f "$out/governance.p7s" ]]; then
  cat >"$out/governance.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>232</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML
  sign "$out/governance.xml" "$out/governance.p7s"
fi

# XML of one <topics> list.
topics_xml() { local t; for t in "$@"; do printf '            <topic>%s</topic>\n' "$t"; done; }

# make_node NAME CN PUB_PARTITION SUB_PARTITION "PUB TOPICS" "SUB TOPICS"
make_node() {
  local name="$1" cn="$2" pub_part="$3" sub_part="$4" pub_topics="$5" sub_topics="$6"
  local dir="$out/$name"
  [[ -f "$dir/permissions.p7s" ]] && return
  mkdir -p "$dir"
  openssl ecparam -name prime256v1 -genkey -noout -out "$dir/key.pem"
  openssl req -new -sha256 -key "$dir/key.pem" -subj "$subject_o/CN=$cn" -out "$dir/cert.csr"
  local validity=(-days "$days")
  [[ -n "$start" ]] && validity=(-startdate "$start" -enddate "$end")
  openssl ca -batch -notext -config "$ca/identity_ca.cnf" "${validity[@]}" \
    -in "$dir/cert.csr" -out "$dir/cert.pem" 2>/dev/null
  rm -f "$dir/cert.csr"
  # The grant's subject, as Fast DDS compares it (RFC 2253 order: most specific first).
  local sn="CN=$cn,O=Telltale fleet"
  local nb na
  nb="$(date -u -d '-1 day' +%Y-%m-%dT%H:%M:%S)"
  na="$(date -u -d "+$days days" +%Y-%m-%dT%H:%M:%S)"
  # shellcheck disable=SC2086
  cat >"$dir/permissions.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$cn">
      <subject_name>$sn</subject_name>
      <validity><not_before>$nb</not_before><not_after>$na</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>232</max></id_range></domains>
        <publish>
          <topics>
$(topics_xml $pub_topics)
          </topics>
          <partitions><partition>$pub_part</partition></partitions>
        </publish>
        <subscribe>
          <topics>
$(topics_xml $sub_topics)
          </topics>
          <partitions><partition>$sub_part</partition></partitions>
        </subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
XML
  sign "$dir/permissions.xml" "$dir/permissions.p7s"
  cp "$ca/identity_ca.pem" "$dir/identity_ca.pem"
  cp "$ca/permissions_ca.pem" "$dir/permissions_ca.pem"
  cp "$out/governance.p7s" "$dir/governance.p7s"
  cp "$out/fleet.salt" "$dir/fleet.salt"
  chmod 0600 "$dir/key.pem" "$dir/fleet.salt"
  chmod 0644 "$dir"/*.pem "$dir"/*.p7s "$dir"/*.xml
  chmod 0600 "$dir/key.pem"
  chmod 0700 "$dir"
  echo "made $dir ($cn)"
}

boat_pub="telltale_boat_attitude telltale_boat_backfill telltale_boat_fix telltale_boat_fix_backfill telltale_boat_wind telltale_node_status"
boat_sub="telltale_shore_ack telltale_shore_fix_ack telltale_alarm_rules telltale_alarm_events"
wear_pub="telltale_wearable_motion telltale_node_status"
wear_sub="telltale_shore_ack telltale_alarm_rules telltale_alarm_events"
shore_pub="telltale_shore_ack telltale_shore_fix_ack telltale_alarm_rules telltale_alarm_events"
shore_sub="telltale_boat_attitude telltale_boat_backfill telltale_boat_fix telltale_boat_fix_backfill telltale_boat_wind telltale_node_status telltale_wearable_motion"

make_node shore telltale-shore tt-shore 'tt-*' "$shore_pub" "$shore_sub"
for b in "${boats[@]}"; do
  t="$(tag "$b")"
  make_node "$b" "node-$t" "tt-$t" tt-shore "$boat_pub" "$boat_sub"
done
for w in "${wearables[@]}"; do
  t="$(tag "$w")"
  make_node "$w" "node-$t" "tt-$t" tt-shore "$wear_pub" "$wear_sub"
done
