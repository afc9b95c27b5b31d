# Shared by scripts/test, fuzz, bench, netns-lab, load and fly-by-hand (the
# launcher, scripts/lab, is Python: scripts/rmslab_launcher/). Source it; don't run it.
# shellcheck shell=bash

RMSLAB_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RMSLAB_BUILD="${RMSLAB_BUILD:-$RMSLAB_ROOT/build}"

rmslab_say() { echo "lab: $*" >&2; }

rmslab_sudo() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else return 1; fi
}

# Configures the project in $RMSLAB_BUILD (Release), once; with
# RMSLAB_WERROR=ON in the environment (.ci/run) warnings are errors, the
# tree configured again if it was made without.
rmslab_configure() {
  if [ ! -f "$RMSLAB_BUILD/build.ninja" ] && [ ! -f "$RMSLAB_BUILD/Makefile" ]; then
    cmake -S "$RMSLAB_ROOT" -B "$RMSLAB_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      ${RMSLAB_WERROR:+-DRMSLAB_WERROR=$RMSLAB_WERROR} >/dev/null
  elif [ -n "${RMSLAB_WERROR:-}" ] &&
       ! grep -qx "RMSLAB_WERROR:BOOL=$RMSLAB_WERROR" "$RMSLAB_BUILD/CMakeCache.txt"; then
    cmake -S "$RMSLAB_ROOT" -B "$RMSLAB_BUILD" -DRMSLAB_WERROR="$RMSLAB_WERROR" >/dev/null
  fi
}

# Configures (once) and builds the project in $RMSLAB_BUILD (Release).
rmslab_build() {
  rmslab_configure
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

# Prints a script's usage: its opening comment block (after the #! line).
rmslab_usage() {
  awk 'NR == 1 { next } /^#/ { sub(/^# ?/, ""); print; next } { exit }' "$1"
}
