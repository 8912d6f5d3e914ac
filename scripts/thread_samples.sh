#!/bin/bash
# Where a multi-threaded run's CPU time goes, thread by thread: runs COMMAND under `perf record`
# (the kernel's CPU clock, 4,000 samples per second of CPU time per thread) and prints, for each
# thread with at least 500 samples (the main thread first), its samples in all, in libjelly and
# spinning in libgomp (waiting for the other threads). The main thread's libjelly samples minus
# the next thread's are the work only the main thread did: the run's serial part (set-up
# included: run twice with different step counts and subtract, docs/benchmarks.md).
#
# Usage: scripts/thread_samples.sh COMMAND [ARGS...]
# Needs perf (Debian: linux-perf) and permission to sample the process (perf_event_paranoid).
set -euo pipefail
if [ $# -eq 0 ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
if ! command -v perf >/dev/null; then
  echo "thread_samples.sh: perf is not installed (Debian: apt install linux-perf)" >&2
  exit 2
fi
data=$(mktemp /tmp/thread-samples.XXXXXX)
trap 'rm -f "$data"' EXIT
perf record -q -o "$data" -- "$@" >/dev/null
perf script -i "$data" -F tid,ip,sym,dso -G 2>/dev/null | awk '
  { tid = $1; all[tid]++; if ($0 ~ /libgomp/) spin[tid]++; else if ($0 ~ /libjelly/) own[tid]++ }
  END { for (t in all) if (all[t] >= 500) print t, all[t], own[t] + 0, spin[t] + 0 }' |
  sort -n | awk '
  BEGIN { print "thread  samples  in libjelly  spinning in libgomp" }
  { printf "%-7s %8d %12d %20d\n", (NR == 1 ? "main" : "worker" NR - 1), $2, $3, $4; own[NR] = $3 }
  END { if (NR >= 2) printf "main thread only (libjelly, main - worker1): %d samples\n", own[1] - own[2] }'
