#!/usr/bin/env bash
# Join benchmark: boats joining a running shore one after another, each timed from
# its "boat_node ready" line (DDS participant and writers up, the first sample about to go out)
# to the shore answering GET /api/v1/boats/ID. Loopback only, its own domain and ports.
#   deploy/bench_join.sh [JOINS (20)] [RUNNING_BOATS (0): boats already sailing beside]
# Prints one line per join and the p50 / p90 / max in ms.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="${TELLTALE_BIN_DIR:-$root/build/bin}"
source "$root/deploy/lib/stop.sh"
joins=${1:-20}; running=${2:-0}
domain=$((100 + $$ % 50))
dir=$(mktemp -d)
token=bench-token
pids=()
cleanup() {
  stop_all "${pids[@]}"
  rm -rf "$dir"
}
trap cleanup EXIT
"$bin/shore_server" --domain "$domain" --http-port 0 --db "$dir/join.db" --coach-token "$token" \
  >"$dir/shore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q ready "$dir/shore.log" && break; sleep 0.1; done
url=$(grep -o 'http://[^ /]*' "$dir/shore.log" || true)
if [ -z "$url" ]; then
  echo "bench_join: the shore did not start within 10 s:" >&2
  cat "$dir/shore.log" >&2
  exit 1
fi
for i in $(seq "$running"); do
  "$bin/boat_node" --domain "$domain" --boat-id "sailing-$i" --log-dir "$dir/log-s$i" \
    >"$dir/s$i.log" 2>&1 &
  pids+=($!)
done
sleep $((running > 0 ? 3 : 1))
now_ms() { echo $(($(date +%s%N) / 1000000)); }
results=()
for i in $(seq "$joins"); do
  id="join-$i"
  "$bin/boat_node" --domain "$domain" --boat-id "$id" --log-dir "$dir/log-$i" >"$dir/$id.log" 2>&1 &
  boat=$!
  ready=""
  seen=""
  for _ in $(seq 1000); do
    if [ -z "$ready" ] && grep -q "boat_node ready" "$dir/$id.log"; then ready=$(now_ms); fi
    if [ -n "$ready" ] && curl -sf -o /dev/null -H "Authorization: Bearer $token" \
      "$url/api/v1/boats/$id"; then
      seen=$(now_ms)
      break
    fi
    sleep 0.005
  done
  if [ "${KEEP:-0}" = 1 ]; then pids+=("$boat"); else stop_all "$boat"; fi
  if [ -z "$seen" ]; then echo "join $i: never seen"; results+=(99999); continue; fi
  echo "join $i: $((seen - ready)) ms"
  results+=($((seen - ready)))
  sleep 0.5
done
printf '%s\n' "${results[@]}" | sort -n | awk '{a[NR]=$1} END {
  p50=a[int((NR+1)/2)]; p90=a[int(NR*0.9+0.999)]; printf "joins %d: p50 %d ms, p90 %d ms, max %d ms\n", NR, p50, p90, a[NR] }'
