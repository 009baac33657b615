#!/usr/bin/env bash
# A fresh machine, timed: a new Debian 12 root made with debootstrap in DIR (default a temporary
# folder; an existing DIR must be empty, so every run starts from nothing), with only what a new
# Debian build machine has (compiler, CMake, git, this machine's Node.js, npm and CA bundle),
# and a clone of this repository's HEAD in it. Then, from nothing (the Debian packages the project
# installs, an empty compiler cache, the build):
#   deploy/bench_fresh.sh [DIR]        `deploy/demo.sh`: prints the seconds to the dashboard link
#                                      and checks that the link's REST API lists boats sailing;
#   deploy/bench_fresh.sh --ci [DIR]   `bash .ci/run` (the README's test command): prints its
#                                      seconds, its per-step line and CTest's summary.
# Needs root (chroot, mounts) and Debian's debootstrap. Nothing but the package mirror and the
# npm registry is contacted; the demo and the tests stay on loopback.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ "$(id -u)" -eq 0 ] || { echo "bench_fresh: needs root (chroot)" >&2; exit 1; }
command -v debootstrap >/dev/null || { echo "bench_fresh: needs debootstrap (apt-get install debootstrap)" >&2; exit 1; }
mode=demo
[ "${1:-}" = "--ci" ] && { mode=ci; shift; }
dir=${1:-$(mktemp -d)}
mkdir -p "$dir"
[ -z "$(ls -A "$dir")" ] || { echo "bench_fresh: $dir is not empty (every run needs a new root)" >&2; exit 1; }
mounts=()
demo=
cleanup() {
  # The demo's own process group: demo.sh and every node it started stop on SIGINT.
  [ -n "$demo" ] && kill -INT -- -"$demo" 2>/dev/null && wait "$demo" 2>/dev/null || true
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do umount "${mounts[i]}" 2>/dev/null || true; done
  # What the tests mounted inside the root (ip netns keeps /run/netns) goes with it.
  umount -R "$dir" 2>/dev/null || true
}
trap cleanup EXIT
debootstrap --variant=minbase bookworm "$dir" http://deb.debian.org/debian >/dev/null
cp /etc/resolv.conf "$dir/etc/resolv.conf"
# The root a mount point of its own, as a machine's / is: the fault tests' mount namespaces
# (`mount --make-rslave /`) refuse a plain folder.
mount --bind "$dir" "$dir"
mounts+=("$dir")
for m in proc sys dev dev/pts dev/shm; do
  mountpoint -q "$dir/$m" || { mount --bind "/$m" "$dir/$m"; mounts+=("$dir/$m"); }
done
# What a new build machine has before the project touches it (not timed).
chroot "$dir" bash -c 'export DEBIAN_FRONTEND=noninteractive; apt-get update -qq &&
  apt-get install -y -qq --no-install-recommends g++ make cmake git ca-certificates >/dev/null'
# Node.js and npm as this machine has them (a build machine of this kind comes with Node.js 20
# and npm 11; Debian 12's own nodejs is 18, which the browser tests refuse).
tar -C / -cf - usr/bin/node usr/bin/npm usr/bin/npx usr/lib/node_modules | tar -C "$dir" -xf -
# TLS through this machine's proxy, if it has one, needs the machine's own CA bundle.
cp /etc/ssl/certs/ca-certificates.crt "$dir/etc/ssl/certs/ca-certificates.crt"
git clone -q "$root" "$dir/root/telltale"
if [ "$mode" = ci ]; then
  start=$(date +%s)
  rc=0
  chroot "$dir" bash -c 'cd /root/telltale && bash .ci/run' >"$dir/root/ci.out" 2>&1 || rc=$?
  end=$(date +%s)
  echo "bash .ci/run on a fresh Debian 12 root: exit $rc after $((end - start)) s"
  grep -E '^test: programs build|tests passed|tests failed' "$dir/root/ci.out" || tail -40 "$dir/root/ci.out"
  exit "$rc"
fi
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
