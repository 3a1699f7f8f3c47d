#!/usr/bin/env bash
# The FE programs with Algorithm 2.2 on 1, 2 and 4 threads, and on 4 logical workers: the same
# output but for timings and the critical path line. Usage: tests/workers_fe.sh PROGRAM ARGS...
set -u
out() { "$@" --quiet 2>&1 | sed -E 's/[0-9.]+ s \(CPU\)/X s (CPU)/; s/on [0-9]+ (threads?|logical workers in turn)/on W/; s/; on [0-9]+ logical workers.*//'; }
first=$(out "$@" --workers 1) || { printf '%s\n' "$first"; exit 1; }
for w in "2" "4" "4 --logical"; do
    other=$(out "$@" --workers $w)
    if [ "$other" != "$first" ]; then
        echo "workers_fe: $* --workers $w differs from --workers 1:"
        diff <(printf '%s\n' "$first") <(printf '%s\n' "$other") | head -n 20
        exit 1
    fi
done
printf '%s\n' "$first" | grep -q 'OK' || { printf '%s\n' "$first"; exit 1; }
