#!/usr/bin/env bash
# Import speed and the shore's memory for a large NMEA 0183 log: generates MB megabytes (default
# 100) of one-second epochs (RMC, GGA, HDT, XDR heel and pitch, MWV wind) of a boat sailing,
# starts a shore, uploads the log with telltale_import and prints the time end to end and the
# shore's resident memory before, after and at its peak. Loopback only.
#   deploy/bench_import.sh [MB] [--bin-dir DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/build/bin"
source "$root/deploy/lib/stop.sh"
mb=100
while [ $# -gt 0 ]; do
  case "$1" in
    --bin-dir) bin=$2; shift 2 ;;
    *) mb=$1; shift ;;
  esac
done
dir=$(mktemp -d)
shore=
trap 'stop_all "$shore"; rm -rf "$dir"' EXIT
perl -e '
  use POSIX qw(strftime);
  my ($limit, $t0) = ($ARGV[0] * 1048576, 1770537600);
  sub nmea { my $b = shift; my $x = 0; $x ^= ord($_) for split //, $b; sprintf("\$%s*%02X\r\n", $b, $x) }
  my ($size, $t) = (0, 0);
  while ($size < $limit) {
    my $hms = strftime("%H%M%S.00", gmtime($t0 + $t));
    my $dmy = strftime("%d%m%y", gmtime($t0 + $t));
    my ($lat, $lon) = (3930 + 0.001 * sin($t * 1e-3), 230 + 0.001 * cos($t * 1e-3));
    my $out = nmea(sprintf("GPRMC,%s,A,%.4f,N,%09.4f,E,6.5,045.0,%s,,,A", $hms, $lat, $lon, $dmy))
      . nmea(sprintf("GPGGA,%s,%.4f,N,%09.4f,E,1,08,0.9,5.0,M,50.0,M,,", $hms, $lat, $lon))
      . nmea(sprintf("HCHDT,%.1f,T", (47 + $t * 0.01) - 360 * int((47 + $t * 0.01) / 360)))
      . nmea(sprintf("IIXDR,A,%.1f,D,ROLL,A,%.1f,D,PTCH", 10 * sin($t * 0.05), 2 * cos($t * 0.05)))
      . nmea("WIMWV,045,R,12.0,N,A");
    print $out; $size += length($out); $t++;
  }
  print STDERR "$t epochs\n";' "$mb" > "$dir/big.nmea" 2> "$dir/gen"
"$bin/shore_server" --domain $((150 + $$ % 50)) --http-port 0 --db "$dir/s.db" --coach-token t \
  --max-import-mb $((mb + 16)) > "$dir/shore" 2>&1 &
shore=$!
for _ in $(seq 100); do grep -q "ready:" "$dir/shore" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*' "$dir/shore" | head -1)
rss() { awk -v k="$1:" '$1 == k {print $2}' /proc/$shore/status; }
before=$(rss VmRSS)
start=$(date +%s.%N)
"$bin/telltale_import" "$dir/big.nmea" --shore "$url" --token t --boat NMEA-BENCH
end=$(date +%s.%N)
echo "log: $(stat -c %s "$dir/big.nmea") bytes, $(cat "$dir/gen")"
echo "upload + import: $(echo "$end - $start" | bc) s"
echo "shore RSS: before ${before} kB, after $(rss VmRSS) kB, peak $(rss VmHWM) kB"
