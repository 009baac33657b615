#!/usr/bin/env bash
# The demo on a fresh machine, timed: a new Debian 12 root made with debootstrap in DIR (default
# a temporary folder; reused when it already holds one), with only what a new Debian build
# machine has (compiler, CMake, git, Node.js and npm), a clone of this repository's HEAD in it,
# then `deploy/demo.sh` run there from nothing: the Debian packages it installs, the build, the
# demo up. Prints the seconds from the start to the dashboard link and checks that the link's
# REST API lists the demo's boats sailing. Needs root (chroot, mounts) and Debian's debootstrap.
# Nothing but the package mirror is contacted; the demo itself stays on loopback.
#   deploy/bench_fresh.sh [DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ "$(id -u)" -eq 0 ] || { echo "bench_fresh: needs root (chroot)" >&2; exit 1; }
command -v debootstrap >/dev/null || { echo "bench_fresh: needs debootstrap (apt-get install debootstrap)" >&2; exit 1; }
dir=${1:-$(mktemp -d)}
mounts=()
demo=
cleanup() {
  # The demo's own process group: demo.sh and every node it started stop on SIGINT.
  [ -n "$demo" ] && kill -INT -- -"$demo" 2>/dev/null && wait "$demo" 2>/dev/null || true
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do umount "${mounts[i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
if [ ! -x "$dir/bin/bash" ]; then
  debootstrap --variant=minbase bookworm "$dir" http://deb.debian.org/debian >/dev/null
fi
cp /etc/resolv.conf "$dir/etc/resolv.conf"
for m in proc sys dev dev/pts dev/shm; do
  mountpoint -q "$dir/$m" || { mount --bind "/$m" "$dir/$m"; mounts+=("$dir/$m"); }
done
# What a new build machine has before the project touches it (not timed).
chroot "$dir" bash -c 'export DEBIAN_FRONTEND=noninteractive; apt-get update -qq &&
  apt-get install -y -qq --no-install-recommends g++ make cmake git nodejs npm ca-certificates \
  >/dev/null'
rm -rf "$dir/root/telltale"
git clone -q "$root" "$dir/root/telltale"
port=$((20000 + $$ % 20000))
start=$(date +%s)
setsid chroot "$dir" env TELLTALE_HTTP_PORT=$port bash -c 'cd /root/telltale && deploy/demo.sh' \
  >"$dir/root/demo.out" 2>&1 &
demo=$!
for _ in $(seq 3600); do grep -q "Dashboard" "$dir/root/demo.out" && break; sleep 0.5; done
grep -q "Dashboard" "$dir/root/demo.out" || { cat "$dir/root/demo.out"; exit 1; }
up=$(date +%s)
echo "demo on a fresh Debian 12 root: dashboard link after $((up - start)) s"
token=$(grep -o 'Coach token: [^ ]*' "$dir/root/demo.out" | cut -d' ' -f3)
sleep 3
curl -sf -H "Authorization: Bearer $token" "http://127.0.0.1:$port/api/v1/boats" |
  grep -o '"id":"[^"]*"\|"sog_m_s":[0-9.]*' | paste -sd' '
