#!/usr/bin/env bash
# block M200 (or the mesh given as $2) with MUMPS against the banded backend: each run must find
# the paper's six branches (exit 0), and every end point on |gamma| = 1 must agree with the
# banded run's to 1e-8 relative to the largest |y| of its branch. MUMPS on 1 rank, then on 2 ranks
# under mpirun (tools/mpirun.sh) when mpirun is there. Usage: bash tests/mumps_ends.sh BLOCK [NXxNY]
set -eu
block=$1
mesh=${2:-10x20}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$block" --quiet --mesh "$mesh" --save "$tmp/banded.txt" > "$tmp/banded.log" || { cat "$tmp/banded.log"; exit 1; }
runs="1"
"$block" --quiet --mesh "$mesh" --solver mumps --save "$tmp/mumps1.txt" > "$tmp/mumps1.log" || { cat "$tmp/mumps1.log"; exit 1; }
if command -v mpirun > /dev/null; then
    sh "$(dirname "$0")/../tools/mpirun.sh" 2 "$block" --quiet --mesh "$mesh" --solver mumps --save "$tmp/mumps2.txt" \
        > "$tmp/mumps2.log" || { cat "$tmp/mumps2.log"; exit 1; }
    runs="1 2"
fi
fail=0
for np in $runs; do
    grep -q "MUMPS on $np rank" "$tmp/mumps$np.log" || { echo "mumps_ends: the $np-rank run did not use MUMPS"; fail=1; }
    # both files: "branch K gamma G" then one line per node; compared branch by branch by K
    worst=$(awk '
        FNR == 1 { f++; b = "" }
        $1 == "branch" { b = $2; line = 0; next }
        b != "" && NF >= 2 {
            line++
            for (i = 1; i <= NF; i++) {
                key = b SUBSEP line SUBSEP i
                if (f == 1) { v[key] = $i; a = $i < 0 ? -$i : $i; if (a > s[b]) s[b] = a }
                else {
                    if (!(key in v)) { missing = 1; continue }
                    d = v[key] - $i; d = d < 0 ? -d : d
                    seen[b] = 1
                    if (s[b] > 0 && d / s[b] > w) w = d / s[b]
                }
            }
        }
        END { n = 0; for (k in seen) n++; if (missing || n != 6) print "mismatch"; else printf "%.1e\n", w }
    ' "$tmp/banded.txt" "$tmp/mumps$np.txt")
    echo "mumps_ends: block --mesh $mesh, MUMPS on $np rank(s) against banded: six branches, largest end-point difference $worst"
    if [ "$worst" = mismatch ] || ! awk -v w="$worst" 'BEGIN { exit !(w <= 1e-8) }'; then fail=1; fi
done
exit $fail
