#!/usr/bin/env bash
# Chart queries on a long session: generates HOURS (default 4) of a boat at 25 Hz as a Vakaros
# Atlas CSV (heel, trim, heading, position, SOG, COG per row), imports it into a fresh shore with
# telltale_import (one session), then loads GET /sessions/1/attitude?max_points=2000 (the review's
# chart request) with wrk, C connections (default 16) for S seconds (default 15), and prints
# wrk's figures and the size of one answer. With BOATS set, a live fleet of that many boats
# (fleet_load, 25 Hz + 10 Hz fixes, one dashboard stream) sails through the whole wrk run, and its
# boat -> SSE latency is printed after wrk's: the live view while an analyst loads charts.
# Needs wrk (apt-get install wrk). Loopback only.
#   [BOATS=200] deploy/bench_chart.sh [HOURS] [CONNECTIONS] [SECONDS] [--bin-dir DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/build/bin"
source "$root/deploy/lib/stop.sh"
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --bin-dir) bin=$2; shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
hours=${args[0]:-4}; conns=${args[1]:-16}; seconds=${args[2]:-15}
command -v wrk >/dev/null || { echo "bench_chart: needs wrk (apt-get install wrk)" >&2; exit 1; }
dir=$(mktemp -d)
shore= load=
trap 'stop_all "$load" "$shore"; rm -rf "$dir"' EXIT
# A boat beating and reaching: heel swinging with the waves (period 4 s) and flipping side every
# 5 minutes (a tack), so every chart bucket has a real lowest and highest sample.
perl -e '
  use POSIX qw(strftime floor);
  my ($n, $t0) = ($ARGV[0] * 3600 * 25, 1770537600);
  print "timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\n";
  for my $i (0 .. $n - 1) {
    my $t = $i / 25;
    my $side = (floor($t / 300) % 2) ? -1 : 1;
    my $ms = sprintf("%03d", ($i % 25) * 40);
    printf "%s.%sZ,%.7f,%.7f,%.2f,%.1f,%.1f,%.2f,%.2f\n",
      strftime("%Y-%m-%dT%H:%M:%S", gmtime($t0 + floor($t))), $ms,
      39.45 + 1e-6 * $t, 0.35 + 1e-6 * $t * $side, 6 + sin($t / 60), 45 + 45 * $side,
      45 + 45 * $side + 3 * sin($t / 7), $side * (15 + 6 * sin($t * 1.5708)), 2 * cos($t * 0.7);
  }' "$hours" > "$dir/long.csv"
"$bin/shore_server" --domain $((150 + $$ % 50)) --http-port 0 --db "$dir/s.db" --coach-token t \
  --max-import-mb 1024 > "$dir/shore" 2>&1 &
shore=$!
for _ in $(seq 100); do grep -q "ready:" "$dir/shore" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*' "$dir/shore" | head -1)
"$bin/telltale_import" "$dir/long.csv" --shore "$url" --token t --boat CHART-BENCH >/dev/null
q="$url/api/v1/sessions/1/attitude?max_points=2000"
curl -sf -H 'Authorization: Bearer t' "$q" > "$dir/one.json"
echo "session: $(curl -sf -H 'Authorization: Bearer t' "$url/api/v1/sessions/1" |
  grep -o '"samples":[0-9]*'); one answer: $(stat -c %s "$dir/one.json") bytes," \
  "$(grep -o '"points":[0-9]*' "$dir/one.json")"
boats=${BOATS:-0}
if [ "$boats" -gt 0 ]; then
  # fleet_load measures from 3 s after its start (discovery); wrk starts 2 s later and ends 1 s
  # before it.
  "$bin/fleet_load" --domain $((150 + $$ % 50)) --shore-url "$url" --token t --shore-pid "$shore" \
    --boats "$boats" --seconds $((seconds + 3)) --sse-clients 1 > "$dir/load.json" &
  load=$!
  sleep 5
fi
wrk -t2 -c"$conns" -d"${seconds}s" --latency -H 'Authorization: Bearer t' "$q"
if [ "$boats" -gt 0 ]; then
  wait $load
  echo "live fleet meanwhile: $boats boats"
  grep -E '"(samples_written|samples_committed_by_shore|latency_ms_p50|latency_ms_p99|shore_cpu_percent_of_one_core)"' "$dir/load.json"
fi
