# Sourced by the deploy scripts: one way to stop the processes a script started.
# stop_all PID...: each is asked to stop (SIGINT, as Ctrl-C does) and given 10 s; one still
# running then is killed and named, so a process stuck in its DDS shutdown cannot hang the
# script. Empty arguments are skipped.
stop_all() {
  local p live=()
  for p in "$@"; do [ -n "$p" ] && live+=("$p"); done
  [ ${#live[@]} -gt 0 ] || return 0
  for p in "${live[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for _ in $(seq 100); do
    local alive=0
    for p in "${live[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  for p in "${live[@]}"; do
    if kill -0 "$p" 2>/dev/null; then
      echo "$(basename "$0"): process $p did not stop within 10 s of SIGINT; killed" >&2
      kill -KILL "$p" 2>/dev/null || true
    fi
    wait "$p" 2>/dev/null || true
  done
}
