#!/usr/bin/env bash
# Packaging test: installs pscbranch as a user would and builds tests/consumer/consumer.c against
# it every supported way, running each build (the program checks its own result and prints the
# version, which must be the header's):
#   a. make install PREFIX=<temporary>, then cc $(pkg-config --cflags pscbranch) consumer.c
#      $(pkg-config --libs pscbranch) with strict warnings; make install DESTDIR=...
#   b. CMake find_package(pscbranch <version> CONFIG) against that prefix (and an impossible
#      version is refused)
#   c. CMake add_subdirectory and FetchContent (from a file:// git URL when the source tree is a
#      git checkout, else SOURCE_DIR) on the source tree
#   d. cmake --install of the source tree, then pkg-config and find_package against that prefix
#   e. make uninstall leaves the prefix empty
# Usage: bash tests/packaging.sh (from anywhere; needs make, cc, pkg-config, cmake >= 3.14, LAPACK).
# Prints `ok`/`FAIL` per step and `N passed, M failed`; exits non-zero when any step fails.
set -u
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/pscbranch-packaging.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT
version=$(awk '/^#define PSCBRANCH_VERSION_(MAJOR|MINOR|PATCH) /{v = v (v == "" ? "" : ".") $3} END{print v}' \
    "$src/pscbranch.h")
CC=${CC:-cc}
passed=0
failed=0

# step NAME CMD...: runs CMD (a function or command) quietly, counts it, shows its output on failure
step() {
    local name=$1 out
    shift
    if out=$("$@" 2>&1); then
        passed=$((passed + 1))
        echo "ok   $name"
    else
        failed=$((failed + 1))
        echo "FAIL $name"
        printf '%s\n' "$out" | tail -n 30
    fi
}

# run_consumer EXE: the consumer runs, succeeds and reports the header's version
run_consumer() {
    local out
    out=$("$1") || { printf '%s\n' "$out"; return 1; }
    printf '%s\n' "$out"
    grep -qx "pscbranch $version" <<<"$out" && grep -qx OK <<<"$out"
}

make_install() {
    make -C "$src" --no-print-directory install PREFIX="$1"
}

installed_files() { # the files make install must write under prefix $1
    local f
    for f in include/pscbranch.h lib/pkgconfig/pscbranch.pc lib/cmake/pscbranch/pscbranchConfig.cmake \
        lib/cmake/pscbranch/pscbranchConfigVersion.cmake share/doc/pscbranch/LICENSE \
        share/doc/pscbranch/README.md share/doc/pscbranch/examples/01_branching.c \
        share/doc/pscbranch/fe/block.c share/doc/pscbranch/fe/README.md share/doc/pscbranch/fc_solve/fc_solve.c \
        share/doc/pscbranch/contrib/psb_sparse.h share/doc/pscbranch/contrib/psb_mumps.h; do
        [ -f "$1/$f" ] || { echo "missing $1/$f"; return 1; }
    done
}

# build_pkgconfig PREFIX LIBDIR: pkg-config's version and flags, a strict C99 build, a run
build_pkgconfig() {
    local prefix=$1 pcdir=$2 cflags libs
    export PKG_CONFIG_PATH=$pcdir
    [ "$(pkg-config --modversion pscbranch)" = "$version" ] || { echo "pkg-config version"; return 1; }
    cflags=$(pkg-config --cflags pscbranch) && libs=$(pkg-config --libs pscbranch) || return 1
    echo "cflags: $cflags  libs: $libs"
    [[ " $cflags " == *" -I$prefix/include "* ]] || { echo "cflags do not name $prefix/include"; return 1; }
    # shellcheck disable=SC2086 # flag lists
    (cd "$work" && $CC -std=c99 -Wall -Wextra -Wpedantic -Werror $cflags "$src/tests/consumer/consumer.c" \
        -o "$work/consumer-pc" $libs) && run_consumer "$work/consumer-pc"
}

destdir_install() { # staged: the files land under DESTDIR, the .pc names the final prefix
    make -C "$src" --no-print-directory install DESTDIR="$work/stage" PREFIX=/opt/pscbranch &&
        installed_files "$work/stage/opt/pscbranch" &&
        grep -qx 'prefix=/opt/pscbranch' "$work/stage/opt/pscbranch/lib/pkgconfig/pscbranch.pc"
}

# cmake_consumer BUILDDIR ARGS...: configure, build and run the consumer project
cmake_consumer() {
    local dir=$1
    shift
    cmake -S "$src/tests/consumer" -B "$dir" "$@" && cmake --build "$dir" && run_consumer "$dir/consumer"
}

find_package_at() { # the package found must be the one in prefix $1
    local log=$work/find-$2.log rc
    cmake_consumer "$work/find-$2" -DCMAKE_PREFIX_PATH="$1" -DPSCBRANCH_CONSUMER=find_package \
        -DPSCBRANCH_VERSION_WANTED="$version" >"$log" 2>&1
    rc=$?
    cat "$log"
    [ $rc -eq 0 ] && grep -q "pscbranch $version from $1/" "$log"
}

version_refused() { # find_package(pscbranch 99.0) must fail
    ! cmake -S "$src/tests/consumer" -B "$work/find-99" -DCMAKE_PREFIX_PATH="$1" \
        -DPSCBRANCH_CONSUMER=find_package -DPSCBRANCH_VERSION_WANTED=99.0
}

fetchcontent() {
    if git -C "$src" rev-parse --verify -q HEAD >/dev/null 2>&1; then
        echo "from file://$src at $(git -C "$src" rev-parse HEAD) (committed state)"
        cmake_consumer "$work/fetch" -DPSCBRANCH_CONSUMER=FetchContent -DPSCBRANCH_GIT_URL="file://$src" \
            -DPSCBRANCH_GIT_TAG="$(git -C "$src" rev-parse HEAD)"
    else
        cmake_consumer "$work/fetch" -DPSCBRANCH_CONSUMER=FetchContent -DPSCBRANCH_SOURCE_DIR="$src"
    fi
}

cmake_install() {
    cmake -S "$src" -B "$work/top" && cmake --install "$work/top" --prefix "$work/cmake-prefix" &&
        installed_files "$work/cmake-prefix"
}

uninstall_all() {
    make -C "$src" --no-print-directory uninstall PREFIX="$1" || return 1
    if [ -n "$(find "$1" -type f)" ]; then
        echo "left behind:"
        find "$1" -type f
        return 1
    fi
}

prefix=$work/prefix
step "make install PREFIX=$prefix" make_install "$prefix"
step "installed files" installed_files "$prefix"
step "pkg-config build and run" build_pkgconfig "$prefix" "$prefix/lib/pkgconfig"
step "make install DESTDIR=... PREFIX=/opt/pscbranch" destdir_install
step "CMake find_package(pscbranch $version CONFIG)" find_package_at "$prefix" make
step "CMake find_package(pscbranch 99.0) refused" version_refused "$prefix"
step "CMake add_subdirectory" cmake_consumer "$work/subdir" -DPSCBRANCH_CONSUMER=add_subdirectory \
    -DPSCBRANCH_SOURCE_DIR="$src"
step "CMake FetchContent" fetchcontent
step "cmake --install" cmake_install
step "pkg-config after cmake --install" build_pkgconfig "$work/cmake-prefix" "$work/cmake-prefix/lib/pkgconfig"
step "CMake find_package after cmake --install" find_package_at "$work/cmake-prefix" cmake
step "make uninstall" uninstall_all "$prefix"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
