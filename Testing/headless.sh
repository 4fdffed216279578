#!/bin/bash
# Runs a command on a virtual X server of its own, for tests that render.
#
# Usage: headless.sh [WIDTHxHEIGHTxDEPTH] COMMAND [ARG...]   (default 1024x768x24)
#
# Why not `xvfb-run -a`: it picks a display number by looking for a free
# lock file and only then starts the server, so two tests that ctest -j
# starts at the same moment can pick the same number; one server then fails
# and its test draws on the other's server, dies with "bad X server
# connection" when that test ends, or hangs. `Xvfb -displayfd` has the
# server pick and lock a free number itself and write it to us.
set -u
screen=1024x768x24
if [[ $# -gt 0 && $1 =~ ^[0-9]+x[0-9]+x[0-9]+$ ]]; then screen=$1; shift; fi
if [ $# -eq 0 ]; then echo "usage: $0 [WxHxD] COMMAND [ARG...]" >&2; exit 2; fi

scratch=$(mktemp -d "${TMPDIR:-/tmp}/mmrtm-headless.XXXXXX")
Xvfb -displayfd 3 -screen 0 "$screen" -nolisten tcp -noreset 3>"$scratch/display" 2>"$scratch/log" &
server=$!
stop() {
  kill "$server" 2>/dev/null && wait "$server" 2>/dev/null
  rm -rf "$scratch"
}
trap stop EXIT
trap 'exit 130' INT TERM

# The server writes its number once it accepts connections (10 s at most).
for _ in $(seq 200); do
  [ -s "$scratch/display" ] && break
  if ! kill -0 "$server" 2>/dev/null; then break; fi
  sleep 0.05
done
if ! [ -s "$scratch/display" ]; then
  echo "headless.sh: Xvfb did not start:" >&2
  cat "$scratch/log" >&2
  exit 1
fi
export DISPLAY=":$(head -1 "$scratch/display")"
"$@"
