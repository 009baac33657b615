#!/usr/bin/env bash
# The demo: a shore server, four simulated boats and a wearable on a private DDS domain (loopback
# only) and the dashboard. Prints the dashboard link with its token; Ctrl-C stops everything cleanly.
# --secure: the same with DDS Security, a fleet PKI made in a temporary folder.
# Environment (each optional): TELLTALE_HTTP_PORT (8080), TELLTALE_DOMAIN (10-99 from the PID),
# TELLTALE_COACH_TOKEN (random), TELLTALE_DB (build/demo.db; the boats' logs go beside it, in
# demo_boat_log/), TELLTALE_BIN_DIR (run these binaries as they are instead of building build/bin).
set -euo pipefail
# Started in the background by a non-interactive shell (`deploy/demo.sh &` in a script, a
# service), the script inherits SIGINT ignored, and bash can neither trap nor reset a signal
# ignored at its entry: `kill -INT` would leave the demo running. Start again with SIGINT's
# default disposition (once: then it is no longer ignored), so that the trap below takes it.
sig_ignored=$(awk '/^SigIgn:/ {print $2}' /proc/$$/status)
if (((16#$sig_ignored >> 1) & 1)); then exec env --default-signal=INT "$BASH" "$0" "$@"; fi
secure=0
[[ "${1:-}" == --secure ]] && secure=1
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${TELLTALE_BIN_DIR:-}
if [[ -z $bin ]]; then
  echo "building (log: $root/build/build.log)..."
  mkdir -p "$root/build"
  "$root/deploy/build.sh" shore_server boat_node wearable_node >"$root/build/build.log" 2>&1 || { tail -n 40 "$root/build/build.log"; exit 1; }
  bin="$root/build/bin"
fi
export TELLTALE_DOMAIN=${TELLTALE_DOMAIN:-$((10 + $$ % 90))}
port=${TELLTALE_HTTP_PORT:-8080}
token=${TELLTALE_COACH_TOKEN:-$(head -c 12 /dev/urandom | base64 | tr '+/' '-_')}
db=${TELLTALE_DB:-$root/build/demo.db}
boat_log=$(dirname "$db")/demo_boat_log
log=$(mktemp -d)
pids=()
stop() {
  local status=${1:-0}
  trap - INT TERM EXIT
  [ ${#pids[@]} -gt 0 ] && kill -INT "${pids[@]}" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$log"
  echo "demo stopped (recording kept in $db)"
  exit "$status"
}
trap 'stop 0' INT TERM
trap 'stop 1' EXIT
sec() { :; }  # sec NODE: the node's --security-dir flag in secured mode, nothing otherwise
if [[ $secure == 1 ]]; then
  "$root/deploy/security/make_fleet_pki.sh" --wearable athlete-1 "$log/pki" \
    ILCA-1 ILCA-2 ILCA-3 ILCA-4 >/dev/null
  sec() { echo "--security-dir=$log/pki/$1"; }
fi
# shellcheck disable=SC2046  # sec's output is one word or none
"$bin/shore_server" --http-port "$port" --db "$db" --coach-token "$token" $(sec shore) \
  >"$log/shore" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -qs "ready" "$log/shore" && break; sleep 0.1; done
grep -q "ready" "$log/shore" || { cat "$log/shore"; exit 1; }
for boat in ILCA-1 ILCA-2 ILCA-3 ILCA-4; do
  # The simulated dinghy carries its sensor on the bow, 1.5 m ahead of and 0.25 m above its
  # centre: installed as a real one would be (--sensor-offset, docs/attitude.md).
  # shellcheck disable=SC2046
  "$bin/boat_node" --boat-id "$boat" --group ILCA7 --log-dir "$boat_log" \
    --sensor-offset 1.5,0,0.25 $(sec "$boat") >"$log/$boat" 2>&1 &
  pids+=($!)
done
# shellcheck disable=SC2046
"$bin/wearable_node" --athlete-id athlete-1 --source sim $(sec athlete-1) >"$log/athlete-1" 2>&1 &
pids+=($!)
url=$(grep -o 'http://[^ ]*' "$log/shore")
echo "Telltale demo on DDS domain $TELLTALE_DOMAIN: shore + 4 boats + 1 wearable" \
  "($(grep -o 'dds_security=[a-z]*' "$log/shore"))"
echo "Dashboard (the fleet map): ${url}#token=${token}&view=map"
echo "Coach token: ${token}   (curl -H 'Authorization: Bearer ${token}' ${url}api/v1/boats)"
echo "Ctrl-C to stop."
rc=0
wait -n "${pids[@]}" || rc=$?
# Ctrl-C reaches every process of the terminal's group at once: a node that stopped on it (0, or
# 130 if killed by it) is the user's stop, not a failure.
if [ "$rc" -eq 0 ] || [ "$rc" -eq 130 ]; then stop 0; fi
echo "a demo process exited unexpectedly (exit $rc):" >&2
tail -n 5 "$log"/* >&2
stop 1
