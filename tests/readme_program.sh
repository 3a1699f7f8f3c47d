#!/bin/sh
# tests/readme_program.sh - the README's first program stays right: extracts the first ```c
# block of README.md, compiles it with the strict warnings of the README's promise, runs it and
# checks its output against the analytic answer (four rays x = (a g, b g), a in {0, 1},
# b in {0, 2}). Exit 0 when it holds, 1 otherwise, with the reason on stderr.
# Environment: CC [cc], LAPACK_LIBS [-llapack -lblas], CFLAGS (added).
set -u
cd "$(dirname "$0")/.."
cc=${CC:-cc}
libs=${LAPACK_LIBS:--llapack -lblas}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT INT TERM
fail() { echo "readme_program: $*" >&2; exit 1; }

awk '/^```c[[:space:]]*$/ && !done { inside = 1; next }
     inside && /^```/ { inside = 0; done = 1; next }
     inside { print }' README.md >"$dir/first.c"
[ -s "$dir/first.c" ] || fail "no \`\`\`c block in README.md"
# shellcheck disable=SC2086
$cc -std=c99 -Wall -Wextra -Wpedantic -Werror -I. ${CFLAGS:-} "$dir/first.c" -o "$dir/first" \
    $libs -lm 2>"$dir/cc.log" || { cat "$dir/cc.log" >&2; fail "the program does not compile"; }
[ -s "$dir/cc.log" ] && { cat "$dir/cc.log" >&2; fail "the compiler said something"; }
"$dir/first" >"$dir/out" 2>"$dir/err" || { cat "$dir/out" "$dir/err" >&2; fail "the program exited non-zero"; }

grep -q '^4 branches leave the point at g = ' "$dir/out" || { cat "$dir/out" >&2; fail "not 4 branches"; }
# the branch lines, -0.000 read as 0.000, in a fixed order: the four rays once each
sed -n 's/^  x = (\(.*\))$/\1/p' "$dir/out" | sed 's/-0\.000/0.000/g' | sort >"$dir/rays"
printf '%s\n' '0.000 g, 0.000 g' '0.000 g, 2.000 g' '1.000 g, 0.000 g' '1.000 g, 2.000 g' >"$dir/expected"
cmp -s "$dir/rays" "$dir/expected" || { cat "$dir/out" >&2; fail "the branches are not the four rays"; }
# branch 0 is the incoming one, x = (g, 2g)
sed -n '2p' "$dir/out" | grep -q '^  x = (1\.000 g, 2\.000 g)$' || fail "branch 0 is not the incoming ray"
echo "readme_program: README's first program compiles without a warning and finds the four rays"
