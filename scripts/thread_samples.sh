#!/bin/bash
# Where a multi-threaded run's CPU time goes, thread by thread: runs COMMAND under `perf record`
# (the kernel's CPU clock, 4,000 samples per second of CPU time per thread) and prints, for the
# main thread and each other thread with at least 500 samples, its samples in all, in jelly's
# code (libjelly, or jelly:: functions in a static build) and spinning in libgomp (waiting for
# the other threads; 0 under OMP_WAIT_POLICY=passive, which waits in the kernel). The main
# thread's samples in jelly's code minus the first worker's are the work only the main thread
# did: the run's serial part, set-up included (run twice with different step counts and
# subtract), plus whatever more a slower main thread took for its share of the split loops.
#
# Usage: scripts/thread_samples.sh COMMAND [ARGS...]
# Needs perf (Debian: linux-perf) and permission to sample the process (perf_event_paranoid).
set -euo pipefail
if [ $# -eq 0 ]; then
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
if ! command -v perf >/dev/null; then
  echo "thread_samples.sh: perf is not installed (Debian: apt install linux-perf)" >&2
  exit 2
fi
data=$(mktemp /tmp/thread_samples.XXXXXX)
trap 'rm -f "$data"' EXIT
perf record -q -e cpu-clock -F 4000 -o "$data" -- "$@" >/dev/null
perf script -i "$data" -F pid,tid,ip,sym,dso -G | awk '
  # "pid/tid address symbol (dso)"
  {
    split($1, ids, "/"); pid = ids[1]; tid = ids[2]; all[tid]++
    if (tid == pid) main = tid
    if ($0 ~ /libgomp/) spin[tid]++
    else if ($0 ~ /libjelly|jelly::/) own[tid]++
  }
  END {
    if (main == "") { print "thread_samples.sh: no samples of the main thread" > "/dev/stderr"; exit 1 }
    print "thread   samples  in jelly  spinning in libgomp"
    printf "%-7s %8d %9d %20d\n", "main", all[main], own[main], spin[main]
    n = 0
    for (t in all) if (t != main && all[t] >= 500) workers[++n] = t
    # (in order of thread id)
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
      if (workers[j] + 0 < workers[i] + 0) { x = workers[i]; workers[i] = workers[j]; workers[j] = x }
    for (i = 1; i <= n; i++) {
      t = workers[i]
      printf "%-7s %8d %9d %20d\n", "worker" i, all[t], own[t], spin[t]
    }
    if (n >= 1)
      printf "main thread only (in jelly, main - worker1): %d samples\n", own[main] - own[workers[1]]
  }'
