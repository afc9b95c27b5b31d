# Shared by scripts/lab and scripts/test. Source it; don't run it.
# shellcheck shell=bash

RMSLAB_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RMSLAB_BUILD="${RMSLAB_BUILD:-$RMSLAB_ROOT/build}"

rmslab_say() { echo "lab: $*" >&2; }

rmslab_sudo() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else return 1; fi
}
# The same as a command prefix, for commands started in the background
# (a shell function in the background would run in a subshell, and signals
# to it would not reach the command).
RMSLAB_SUDO=()
if [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null; then RMSLAB_SUDO=(sudo); fi

# Configures (once) and builds the project in $RMSLAB_BUILD (Release).
rmslab_build() {
  if [ ! -f "$RMSLAB_BUILD/build.ninja" ] && [ ! -f "$RMSLAB_BUILD/Makefile" ]; then
    cmake -S "$RMSLAB_ROOT" -B "$RMSLAB_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  fi
  cmake --build "$RMSLAB_BUILD" --parallel "$(nproc)"
}

# LCM's UDP multicast needs a route to 224.0.0.0/4. A machine with a default
# route has one; a bare host or network namespace may not. Adds one on
# loopback when missing, and says so.
rmslab_ensure_multicast_route() {
  if ip route get 239.255.76.67 >/dev/null 2>&1; then return 0; fi
  rmslab_say "this machine has no route for multicast (224.0.0.0/4); adding one on loopback:"
  rmslab_say "  ip route add 224.0.0.0/4 dev lo"
  if ! rmslab_sudo ip route add 224.0.0.0/4 dev lo; then
    rmslab_say "could not add the route (need root or sudo). Add it by hand, then run again."
    return 1
  fi
}

# The frame rate of a configuration file (session.frame_rate_hz).
rmslab_frame_rate() {
  awk '/^\[/ { sec = $0 } sec == "[session]" && $1 == "frame_rate_hz" { print $3; exit }' "$1"
}

# ---- Session processes (scripts/lab demo, replay) --------------------------
# A process runs on a host: "localhost", "netns:NAME" (a network namespace on
# this machine) or "ssh:[USER@]HOST". Its output goes to
# $RMSLAB_OUT/logs/NAME.log; it is stopped with SIGINT (pipeline order, the
# recorder last) and its exit code is appended to $RMSLAB_OUT/run/exit_codes.
RMSLAB_PIDS=()
RMSLAB_NAMES=()
RMSLAB_HOSTS=()
RMSLAB_STOPPED=0
RMSLAB_OUT=""
RMSLAB_REMOTE_RUN=""   # on ssh hosts: where pid files go

# rmslab_start NAME HOST CMD...
rmslab_start() {
  local name="$1" host="$2"; shift 2
  local log="$RMSLAB_OUT/logs/$name.log"
  case "$host" in
    ""|localhost) "$@" >"$log" 2>&1 & ;;
    netns:*) "${RMSLAB_SUDO[@]}" nsenter --net="/var/run/netns/${host#netns:}" -- "$@" >"$log" 2>&1 & ;;
    ssh:*)
      local quoted; quoted=$(printf '%q ' "$@")
      ssh -o BatchMode=yes "${host#ssh:}" \
        "mkdir -p $RMSLAB_REMOTE_RUN && echo \$\$ >$RMSLAB_REMOTE_RUN/$name.pid && exec $quoted" >"$log" 2>&1 & ;;
    *) rmslab_say "unknown host '$host' for $name"; return 1 ;;
  esac
  RMSLAB_PIDS+=("$!"); RMSLAB_NAMES+=("$name"); RMSLAB_HOSTS+=("$host")
}

# The session's epoch (wall clock, us since 1970): every process numbers its
# frames from it (docs/protocol.md "Frame numbers"), so one restarted after
# a fault carries on the numbering and its peers count the frames it missed.
RMSLAB_EPOCH_US=""

# rmslab_start_supervised NAME HOST CMD...: as rmslab_start, for the
# session's processes on this machine (localhost or netns:): when the process
# ends other than by the session's stop -- killed, crashed, a non-zero exit
# -- it is started again at once with RMSLAB_RESTART=N in its environment,
# and a line "NAME N EXIT_CODE DOWN_AT READY_AT" (wall clock, s) goes to
# run/restarts (docs/sessions.md "Faults"). On ssh hosts: rmslab_start.
rmslab_start_supervised() {
  local name="$1" host="$2"; shift 2
  case "$host" in
    ssh:*) rmslab_start "$name" "$host" "$@"; return ;;
  esac
  rmslab_supervise "$name" "$host" "$@" &
  RMSLAB_PIDS+=("$!"); RMSLAB_NAMES+=("$name"); RMSLAB_HOSTS+=("$host")
}

# rmslab_exec_on HOST N CMD...: becomes CMD on HOST (this machine or a
# network namespace) with the session's epoch and RMSLAB_RESTART=N in its
# environment. Start it in the background (`rmslab_exec_on ... &`): the
# subshell is replaced by the command, so $! is the command's pid.
rmslab_exec_on() {
  local host="$1" n="$2"; shift 2
  local envs=(env "RMSLAB_SESSION_EPOCH_US=$RMSLAB_EPOCH_US" "RMSLAB_RESTART=$n" "RMSLAB_SESSION_ID=${RMSLAB_SESSION_ID:-}")
  case "$host" in
    ""|localhost) exec "${envs[@]}" "$@" ;;
    netns:*) exec "${RMSLAB_SUDO[@]}" nsenter --net="/var/run/netns/${host#netns:}" -- "${envs[@]}" "$@" ;;
    *) rmslab_say "unknown host '$host'"; exit 2 ;;
  esac
}

rmslab_supervise() {  # (in the background) NAME HOST CMD...
  local name="$1" host="$2"; shift 2
  local log="$RMSLAB_OUT/logs/$name.log" n=0 rc=0 pid t_down="" readies=0 i
  while :; do
    rmslab_exec_on "$host" "$n" "$@" >>"$log" 2>&1 &
    pid=$!
    echo "$pid" >"$RMSLAB_OUT/run/$name.pid"
    echo "$name $pid" >>"$RMSLAB_OUT/run/pids"
    if [ "$n" -gt 0 ]; then
      # Restarted: the time until it says it is ready again.
      for i in $(seq 1 600); do
        [ "$(grep -c '\] ready: ' "$log" 2>/dev/null || true)" -gt "$readies" ] && break
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.02
      done
      echo "$name $n $rc $t_down $(date +%s.%N)" >>"$RMSLAB_OUT/run/restarts"
    fi
    rc=0
    wait "$pid" || rc=$?
    [ -e "$RMSLAB_OUT/run/stopping" ] && return "$rc"
    [ "$rc" = 0 ] && return 0
    t_down=$(date +%s.%N)
    readies=$(grep -c '\] ready: ' "$log" 2>/dev/null || true)
    n=$((n + 1))
    rmslab_say "$name ended with code $rc mid-session; restarting it (restart $n)"
  done
}

# rmslab_signal INDEX SIGNAL: to the process, wherever it runs (a
# supervised one through its pid file).
rmslab_signal() {
  local i="$1" sig="$2"
  local pidfile="$RMSLAB_OUT/run/${RMSLAB_NAMES[$i]}.pid"
  if [ -f "$pidfile" ]; then
    kill "-$sig" "$(cat "$pidfile")" 2>/dev/null || true
    return 0
  fi
  case "${RMSLAB_HOSTS[$i]}" in
    ssh:*) ssh -o BatchMode=yes "${RMSLAB_HOSTS[$i]#ssh:}" \
             "kill -$sig \$(cat $RMSLAB_REMOTE_RUN/${RMSLAB_NAMES[$i]}.pid) 2>/dev/null" 2>/dev/null || true ;;
    *) kill "-$sig" "${RMSLAB_PIDS[$i]}" 2>/dev/null || true ;;
  esac
}

# rmslab_wait_exit PID NAME: up to 5 s, then SIGKILL; records the exit code.
rmslab_wait_exit() {
  local pid="$1" name="$2" t=0
  while kill -0 "$pid" 2>/dev/null; do
    sleep 0.1; t=$((t + 1))
    if [ "$t" -ge 50 ]; then rmslab_say "$name did not stop; killing it"; kill -KILL "$pid" 2>/dev/null || true; fi
  done
  local rc=0
  wait "$pid" 2>/dev/null || rc=$?
  echo "$name $rc" >>"$RMSLAB_OUT/run/exit_codes"
}

# Stops every started process: the pipeline first, the recorder last so it
# records everyone's final status report.
rmslab_stop_all() {
  [ "$RMSLAB_STOPPED" = 1 ] && return 0
  RMSLAB_STOPPED=1
  [ -n "$RMSLAB_OUT" ] && touch "$RMSLAB_OUT/run/stopping"  # supervised processes are not restarted now
  local i
  for i in "${!RMSLAB_PIDS[@]}"; do
    [ "${RMSLAB_NAMES[$i]}" = lcm-logger ] || rmslab_signal "$i" INT
  done
  for i in "${!RMSLAB_PIDS[@]}"; do
    [ "${RMSLAB_NAMES[$i]}" = lcm-logger ] || rmslab_wait_exit "${RMSLAB_PIDS[$i]}" "${RMSLAB_NAMES[$i]}"
  done
  sleep 0.3
  for i in "${!RMSLAB_PIDS[@]}"; do
    [ "${RMSLAB_NAMES[$i]}" = lcm-logger ] || continue
    rmslab_signal "$i" INT
    rmslab_wait_exit "${RMSLAB_PIDS[$i]}" lcm-logger
  done
}

# rmslab_wait_ready NAME...: until each has logged "ready:" (which works on
# any host) and the session's log is open; 15 s at most.
rmslab_wait_ready() {
  local t p i ready
  for t in $(seq 1 150); do
    ready=1
    for p in "$@"; do grep -q "\] ready: " "$RMSLAB_OUT/logs/$p.log" 2>/dev/null || ready=0; done
    [ -f "$RMSLAB_OUT/lcmlog" ] || ready=0
    [ "$ready" = 1 ] && return 0
    for i in "${!RMSLAB_PIDS[@]}"; do
      if ! kill -0 "${RMSLAB_PIDS[$i]}" 2>/dev/null; then
        rmslab_say "${RMSLAB_NAMES[$i]} exited at start; its log:"; tail -n 20 "$RMSLAB_OUT/logs/${RMSLAB_NAMES[$i]}.log" >&2
        return 1
      fi
    done
    sleep 0.1
  done
  rmslab_say "processes were not ready within 15 s (logs in $RMSLAB_OUT/logs)"
  return 1
}

# rmslab_check_exit_codes: says which process ended badly; 0 if none.
rmslab_check_exit_codes() {
  local bad=0 name rc
  while read -r name rc; do
    if [ "$rc" != 0 ]; then rmslab_say "$name exited with $rc (see $RMSLAB_OUT/logs/$name.log)"; bad=1; fi
  done <"$RMSLAB_OUT/run/exit_codes"
  return "$bad"
}

# rmslab_manifest_value SESSION KEY: a string value from manifest.json ("" if none).
rmslab_manifest_value() {
  [ -f "$1/manifest.json" ] || { echo ""; return 0; }
  grep -o "\"$2\": \"[^\"]*\"" "$1/manifest.json" | head -n 1 | sed 's/.*: "\(.*\)"/\1/'
}

# rmslab_check_hosts URL REMOTE_BIN HOST...: before a session on several
# hosts, each must be reachable, have rmslab built, and route multicast.
rmslab_check_hosts() {
  local url="$1" rbin="$2"; shift 2
  local h seen="" ok=0
  for h in "$@"; do
    case " $seen " in *" $h "*) continue ;; esac
    seen="$seen $h"
    case "$h" in
      localhost) ;;
      netns:*)
        if ! ip netns list 2>/dev/null | grep -qw "${h#netns:}"; then
          rmslab_say "host $h: no such network namespace (ip netns list)"; ok=1; continue
        fi
        if ! rmslab_sudo ip netns exec "${h#netns:}" ip route get 239.255.76.67 >/dev/null 2>&1; then
          rmslab_say "host $h: no route for multicast in the namespace (ip route add 224.0.0.0/4 dev IFACE)"; ok=1
        fi ;;
      ssh:*)
        if ! ssh -o BatchMode=yes -o ConnectTimeout=5 "${h#ssh:}" true 2>/dev/null; then
          rmslab_say "host $h: cannot reach it by ssh without a password"; ok=1; continue
        fi
        if ! ssh -o BatchMode=yes "${h#ssh:}" "test -x $rbin/dynamics_proc/dynamics_proc" 2>/dev/null; then
          rmslab_say "host $h: rmslab is not built at $rbin (the lab file's [remote] build)"; ok=1
        fi
        if ! ssh -o BatchMode=yes "${h#ssh:}" "ip route get 239.255.76.67" >/dev/null 2>&1; then
          rmslab_say "host $h: no route for multicast"; ok=1
        fi ;;
    esac
  done
  [ "$ok" = 0 ] && rmslab_say "hosts checked:$seen (LCM $url)"
  return "$ok"
}
