#!/bin/sh
# shellcheck disable=SC2317 # the has_* checks are called indirectly, by name
# Checks that the tools a make target needs are there, installs the missing ones with apt-get
# when it can (as root, or through passwordless sudo), otherwise stops with the command to run.
# Silent when everything is present.
#
#   tools/deps.sh NEED...      NEED: cc (the C compiler $CC), cxx (the C++ compiler $CXX),
#                              lapack (a program calling dgetrf_ links with $LAPACK_LIBS and
#                              runs), gnuplot, fuzz (clang with libFuzzer: a fuzz target links
#                              with -fsanitize=fuzzer,address,undefined), suitesparse (UMFPACK and
#                              KLU headers); a trailing '?' marks a need optional (hdf5?): it is
#                              installed along with the others when they are, never an error.
#
# Environment: CC, CXX, LAPACK_LIBS as make passes them; DEPS_NO_INSTALL=1 only reports.
# Exit status 0 when every required need is met, 1 otherwise.
set -u
CC=${CC:-cc}
CXX=${CXX:-c++}
LAPACK_LIBS=${LAPACK_LIBS:--llapack -lblas}
tmp=""
cleanup() { [ -n "$tmp" ] && rm -rf "$tmp"; }
trap cleanup EXIT

# has_NEED: 0 when the need is met
has_cc() { command -v "${CC%% *}" >/dev/null 2>&1; }
has_cxx() { command -v "${CXX%% *}" >/dev/null 2>&1; }
has_gnuplot() { command -v gnuplot >/dev/null 2>&1; }
has_fuzz() {
    command -v clang >/dev/null 2>&1 || return 1
    [ -n "$tmp" ] || tmp=$(mktemp -d "${TMPDIR:-/tmp}/pscbranch-deps.XXXXXX") || return 1
    printf '%s\n' '#include <stddef.h>' '#include <stdint.h>' \
        'int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }' \
        >"$tmp/f.c"
    clang -fsanitize=fuzzer,address,undefined "$tmp/f.c" -o "$tmp/f" >"$tmp/log" 2>&1
}
has_hdf5() { command -v pkg-config >/dev/null 2>&1 && pkg-config --exists hdf5; }
has_suitesparse() { [ -f /usr/include/suitesparse/umfpack.h ] && [ -f /usr/include/suitesparse/klu.h ]; }
has_lapack() {
    has_cc || return 1
    [ -n "$tmp" ] || tmp=$(mktemp -d "${TMPDIR:-/tmp}/pscbranch-deps.XXXXXX") || return 1
    cat >"$tmp/t.c" <<'EOF'
extern void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
int main(void)
{
    int n = 2, ipiv[2], info = -1;
    double a[4] = {1, 4, 2, 3}; /* LU with a row interchange: U = [4 3; 0 1.25] */
    dgetrf_(&n, &n, a, &n, ipiv, &info);
    return !(info == 0 && ipiv[0] == 2 && a[0] == 4 && a[3] == 1.25);
}
EOF
    # shellcheck disable=SC2086 # CC and LAPACK_LIBS are word lists, as in make
    $CC "$tmp/t.c" -o "$tmp/t" $LAPACK_LIBS -lm >"$tmp/log" 2>&1 && "$tmp/t"
}

# Debian/Ubuntu package providing a need
package_of() {
    case "$1" in
    cc)
        case "${CC%% *}" in
        *clang*) echo clang ;;
        *) echo build-essential ;;
        esac ;;
    cxx)
        case "${CXX%% *}" in
        *clang*) echo "clang g++" ;; # clang++ links with GCC's libstdc++
        *) echo g++ ;;
        esac ;;
    lapack) echo "liblapack-dev libblas-dev" ;;
    gnuplot) echo gnuplot-nox ;;
    hdf5) echo "pkg-config libhdf5-dev" ;;
    suitesparse) echo "libsuitesparse-dev" ;;
    fuzz) # libFuzzer ships with clang's runtime, packaged per clang version
        v=$(clang --version 2>/dev/null | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -n 1)
        echo "clang libclang-rt-${v:-14}-dev" ;;
    *) echo "tools/deps.sh: unknown need '$1'" >&2; exit 2 ;;
    esac
}

# what a need is, for messages
describe() {
    case "$1" in
    cc) echo "the C compiler $CC" ;;
    cxx) echo "the C++ compiler $CXX" ;;
    lapack) echo "LAPACK/BLAS (a program calling dgetrf_ linked with $LAPACK_LIBS)" ;;
    gnuplot) echo "gnuplot" ;;
    hdf5) echo "HDF5 through pkg-config" ;;
    suitesparse) echo "SuiteSparse (UMFPACK, KLU)" ;;
    fuzz) echo "clang with libFuzzer" ;;
    esac
}

check() { # fills missing and optional (the packages of the unmet needs) and what (their names)
    missing=""
    optional=""
    what=""
    for need in "$@"; do
        name=${need%\?}
        if ! "has_$name"; then
            if [ "$name" = "$need" ]; then
                missing="$missing $(package_of "$name")"
                what="$what${what:+, }$(describe "$name")"
            else
                optional="$optional $(package_of "$name")"
            fi
        fi
    done
}

check "$@"
[ -z "$missing" ] && [ -z "$optional" ] && exit 0

# something is missing: how could we install it?
can_install=0
sudo=""
if command -v apt-get >/dev/null 2>&1 && [ "${DEPS_NO_INSTALL:-0}" != 1 ]; then
    if [ "$(id -u)" -eq 0 ]; then
        can_install=1
    elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        can_install=1
        sudo="sudo -n"
    fi
fi
if [ -z "$missing" ] && [ $can_install = 0 ]; then # only optional ones, and no way to install them
    echo "note: optional support skipped (missing:$optional); to add it: sudo apt-get install -y$optional"
    exit 0
fi
if [ $can_install = 0 ]; then
    if command -v apt-get >/dev/null 2>&1; then
        echo "error: missing $what. Install with:" >&2
        echo "    sudo apt-get install -y$missing$optional" >&2
    else
        echo "error: missing $what (Debian/Ubuntu packages:$missing; no apt-get here:" >&2
        echo "    install your system's equivalents)" >&2
    fi
    [ -n "$tmp" ] && [ -s "$tmp/log" ] && sed 's/^/    /' "$tmp/log" | head -n 5 >&2
    exit 1
fi

packages="$missing$optional"
echo "installing with apt-get:$packages"
export DEBIAN_FRONTEND=noninteractive
# shellcheck disable=SC2086 # sudo and packages are word lists
if ! $sudo apt-get install -y --no-install-recommends $packages && [ -n "$missing" ]; then
    # a fresh machine has no package lists yet (not retried for optional packages alone: an
    # offline machine would pay for it at every make)
    $sudo apt-get update && $sudo apt-get install -y --no-install-recommends $packages
fi
check "$@"
if [ -n "$missing" ]; then
    echo "error: still missing after apt-get: $what" >&2
    [ -n "$tmp" ] && [ -s "$tmp/log" ] && sed 's/^/    /' "$tmp/log" | head -n 5 >&2
    exit 1
fi
[ -n "$optional" ] && echo "note: optional support skipped (could not install$optional)"
exit 0
