#!/usr/bin/env bash
# Runs the test programs and the example smoke tests given as arguments, adds up their
# `RESULT passed=N failed=M` lines, and ends with the line `N passed, M failed`.
# An argument of the form 'smoke:CMD...' counts as one test: it passes when CMD exits 0.
set -u
passed=0
failed=0
for item in "$@"; do
    case "$item" in
    smoke:*)
        cmd=${item#smoke:}
        out=$(eval "$cmd" 2>&1)
        rc=$?
        if [ $rc -eq 0 ]; then
            passed=$((passed + 1))
            echo "ok   $cmd"
        else
            failed=$((failed + 1))
            echo "FAIL $cmd (exit $rc)"
            printf '%s\n' "$out" | tail -n 20
        fi
        ;;
    *)
        out=$("$item" 2>&1)
        rc=$?
        line=$(printf '%s\n' "$out" | grep '^RESULT passed=' | tail -n 1)
        if [ -z "$line" ]; then
            failed=$((failed + 1))
            echo "FAIL $item: no RESULT line (exit $rc)"
            printf '%s\n' "$out" | tail -n 20
            continue
        fi
        p=$(printf '%s' "$line" | sed 's/.*passed=\([0-9]*\).*/\1/')
        f=$(printf '%s' "$line" | sed 's/.*failed=\([0-9]*\).*/\1/')
        if [ "$f" -eq 0 ] && [ $rc -ne 0 ]; then f=1; fi
        passed=$((passed + p))
        failed=$((failed + f))
        printf '%s\n' "$out" | grep -v '^RESULT' | head -n 40
        echo "$( [ "$f" -eq 0 ] && echo 'ok  ' || echo 'FAIL') $item: $p passed, $f failed"
        ;;
    esac
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
