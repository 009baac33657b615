#!/usr/bin/env bash
# CPU and memory of one boat node: 100 Hz simulated IMU, 25 Hz publishing to a shore,
# session log on, for SECONDS (default 60). Loopback only. --secure: both with DDS Security (a
# fleet PKI made in the temporary folder by deploy/security/make_fleet_pki.sh).
set -euo pipefail
secure=()
shore_secure=()
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/build/bin"
source "$root/deploy/lib/stop.sh"
if [[ "${1:-}" == --secure ]]; then shift; secure=(1); fi
seconds=${1:-60}
domain=$((150 + $$ % 50))
dir=$(mktemp -d)
shore= boat=
trap 'stop_all "$boat" "$shore"; rm -rf "$dir"' EXIT
if [[ ${#secure[@]} -gt 0 ]]; then
  "$root/deploy/security/make_fleet_pki.sh" "$dir/pki" bench >/dev/null
  secure=(--security-dir "$dir/pki/bench")
  shore_secure=(--security-dir "$dir/pki/shore")
fi
"$bin/shore_server" --domain "$domain" --http-port 0 --db "$dir/s.db" --coach-token t \
  "${shore_secure[@]}" >"$dir/shore" 2>&1 &
shore=$!
sleep 1
"$bin/boat_node" --domain "$domain" --boat-id bench --imu-rate-hz 100 --rate-hz 25 \
  --log-dir "$dir/log" "${secure[@]}" >"$dir/boat" 2>&1 &
boat=$!
sleep 3  # discovery and start-up
ticks=$(getconf CLK_TCK)
read -r u0 s0 < <(awk '{print $14, $15}' /proc/$boat/stat)
sleep "$seconds"
read -r u1 s1 < <(awk '{print $14, $15}' /proc/$boat/stat)
rss_kb=$(awk '/VmRSS/ {print $2}' /proc/$boat/status)
hwm_kb=$(awk '/VmHWM/ {print $2}' /proc/$boat/status)
threads=$(awk '/Threads/ {print $2}' /proc/$boat/status)
stop_all "$boat"
cpu=$(awk -v d=$((u1 + s1 - u0 - s0)) -v t="$ticks" -v s="$seconds" 'BEGIN {printf "%.2f", 100 * d / t / s}')
echo "boat_node over ${seconds}s: CPU ${cpu}% of one core, RSS $((rss_kb / 1024)) MB (peak $((hwm_kb / 1024)) MB), $threads threads"
tail -n 1 "$dir/boat"
