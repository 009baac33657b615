#!/usr/bin/env bash
# Load benchmark: N boats x 25 Hz attitude + 10 Hz GNSS fixes (fleet_load's defaults) for
# S seconds through real DDS into one shore, with SSE clients connected; optionally wrk against
# GET /api/v1/boats meanwhile. Loopback only.
#   [SHORE_ARGS="--commit-ms 1000"] deploy/bench_fleet.sh [BOATS] [SECONDS] [SSE_CLIENTS] [WRK_SECONDS]
# Losses are located in its output: shore_udp_receive_drops (the kernel, before DDS) and
# shore_store_dropped (the store's bounded queue).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/build/bin"
source "$root/deploy/lib/stop.sh"
boats=${1:-200}; seconds=${2:-300}; sse=${3:-1}; wrk_s=${4:-0}
if [ "$wrk_s" -gt 0 ] && ! command -v wrk >/dev/null; then
  echo "bench_fleet: the wrk part needs wrk (apt-get install wrk)" >&2
  exit 2
fi
domain=$((150 + $$ % 50))
dir=$(mktemp -d)
token=bench-token
"$bin/shore_server" --domain "$domain" --http-port 0 --db "$dir/bench.db" --coach-token "$token" \
  --max-streams $((sse + 8)) ${SHORE_ARGS:-} >"$dir/shore.log" 2>&1 &
shore=$!
trap 'stop_all "${load:-}" "$shore"; rm -rf "$dir"' EXIT
for _ in $(seq 100); do grep -q ready "$dir/shore.log" && break; sleep 0.1; done
url=$(grep -o 'http://[^ /]*' "$dir/shore.log")
"$bin/fleet_load" --domain "$domain" --shore-url "$url" --token "$token" --shore-pid "$shore" \
  --boats "$boats" --seconds "$seconds" --sse-clients "$sse" >"$dir/load.json" &
load=$!
if [ "$wrk_s" -gt 0 ]; then
  sleep 8
  echo "wrk: GET /api/v1/boats with $sse SSE clients and $boats boats x 25 Hz streaming"
  wrk -t2 -c16 -d"${wrk_s}s" --latency -H "Authorization: Bearer $token" "$url/api/v1/boats" |
    grep -E "Requests/sec|Latency|50%|99%|requests in"
fi
wait $load
cat "$dir/load.json"
echo "stored in SQLite: $(sqlite3 "$dir/bench.db" 'SELECT COUNT(*) FROM attitude') samples, $(sqlite3 "$dir/bench.db" 'SELECT COUNT(*) FROM fixes') fixes"
