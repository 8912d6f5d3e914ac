#!/usr/bin/env bash
# Runs a test program under xvfb-run. `xvfb-run -a` starts looking for a free display at :99 and
# races with other xvfb-run users of a shared machine (a display taken between its check and the
# server's start ends as "cannot open display"): this starts at a random display number and tries
# again, up to three times, when the X server rather than the test failed.
#   xvfb_test.sh PROGRAM ARGS...
set -uo pipefail
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for attempt in 1 2 3; do
  xvfb-run -a -n $((100 + RANDOM % 800)) -s "-screen 0 1280x1024x24" "$@" 2>&1 | tee "$log"
  status=${PIPESTATUS[0]}
  if [ "$status" -eq 0 ] ||
     ! grep -qE "needs a display|Failed to open display|Xvfb failed to start|cannot open display" "$log"; then
    exit "$status"
  fi
  echo "xvfb_test.sh: the X server failed (attempt $attempt), trying another display" >&2
  sleep 1
done
exit "$status"
