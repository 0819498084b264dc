#!/usr/bin/env bash
# Relocation test, as a user would run reachc (called from .ci/run):
#
#   1. copy the repository's tracked files to a temporary directory and `cargo install` reachc
#      from there (release, --locked), then delete the copy and the build directory;
#   2. with a fresh, empty HOME (cargo and rustup still found through CARGO_HOME and
#      RUSTUP_HOME; REACHC_TARGET_DIR and XDG_CACHE_HOME unset), run the installed reachc on a
#      copy of specs/pendulum.sde outside the repository with the compiled backend (a cold
#      cache: the runtime is compiled once): exit 0, and JSON byte-identical to
#      `--backend interp`;
#   3. run it again with cargo and rustc replaced by programs that record their calls and fail:
#      it must succeed without calling them, write nothing in the cache, print nothing on
#      stderr, and give the same JSON;
#   4. no file in the cache names the temporary directory or the repository;
#   5. a warm compiled run against the interpreter, whole process, median of 5 runs each.
#
# One install and one cold runtime build; prints the duration of each step and the total.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
start=$(date +%s)
step() { printf 'relocation: %s (%ds)\n' "$1" "$(($(date +%s) - start))"; }
fail() { printf 'relocation: FAILED: %s\n' "$1" >&2; exit 1; }

command -v git >/dev/null || fail "git is required (to list the tracked files)"
real_home=${HOME:?HOME must be set}
export CARGO_HOME="${CARGO_HOME:-$real_home/.cargo}"
export RUSTUP_HOME="${RUSTUP_HOME:-$real_home/.rustup}"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/reachc-relocation.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# 1. Install from a copy of the tracked files, then delete the copy.
copy="$tmp/checkout"
mkdir -p "$copy"
(cd "$repo" && git ls-files -z | while IFS= read -r -d '' f; do
    if [ -e "$f" ]; then printf '%s\0' "$f"; fi
done | tar --null -T - -cf -) | tar -C "$copy" -xf -
[ -f "$copy/cli/Cargo.toml" ] || fail "the copy has no cli/Cargo.toml"
step "copied $(cd "$copy" && find . -type f | wc -l) tracked files"
CARGO_TARGET_DIR="$tmp/install-target" cargo install --quiet --locked --path "$copy/cli" \
    --root "$tmp/install"
reachc="$tmp/install/bin/reachc"
[ -x "$reachc" ] || fail "cargo install produced no $reachc"
work="$tmp/work"
mkdir -p "$work"
cp "$copy/specs/pendulum.sde" "$work/pendulum.sde"
rm -rf "$copy" "$tmp/install-target"
step "installed reachc; deleted the copy it was built from"

# 2. A fresh HOME, the default cache ($HOME/.cache/reachc), a cold compiled run.
export HOME="$tmp/home"
mkdir -p "$HOME"
unset REACHC_TARGET_DIR XDG_CACHE_HOME CARGO_TARGET_DIR CARGO RUSTC RUSTC_WRAPPER
cd "$work"
"$reachc" run pendulum.sde -o out-compiled >/dev/null 2>"$tmp/cold.err" \
    || { cat "$tmp/cold.err" >&2; fail "the cold compiled run failed"; }
step "cold compiled run (the runtime compiled once): ok; stderr: $(head -n 1 "$tmp/cold.err")"
"$reachc" run --backend interp pendulum.sde -o out-interp >/dev/null \
    || fail "the interpreter run failed"
same_json() { # DIR_A DIR_B
    local a b
    a=$(cd "$1" && ls ./*.json)
    b=$(cd "$2" && ls ./*.json)
    [ -n "$a" ] && [ "$a" = "$b" ] || fail "$1 and $2 hold different results: [$a] [$b]"
    for f in $a; do cmp -s "$1/$f" "$2/$f" || fail "$1/$f differs from $2/$f"; done
}
same_json out-compiled out-interp
step "compiled and interpreted JSON byte-identical ($(cd out-interp && ls ./*.json | wc -l) files)"

# 3. Again, with cargo and rustc unusable: the cached binary runs, nothing is written.
cache="$HOME/.cache/reachc"
[ -d "$cache/crates/pendulum" ] || fail "no crate in the default cache $cache"
fake="$tmp/no-toolchain"
mkdir -p "$fake"
for tool in cargo rustc; do
    printf '#!/bin/sh\necho "%s $*" >> "%s/calls"\nexit 1\n' "$tool" "$fake" > "$fake/$tool"
    chmod +x "$fake/$tool"
done
touch "$tmp/before-warm"
sleep 1
PATH="$fake:$PATH" CARGO="$fake/cargo" RUSTC="$fake/rustc" \
    "$reachc" run pendulum.sde -o out-warm >/dev/null 2>"$tmp/warm.err" \
    || { cat "$tmp/warm.err" >&2; fail "the warm run failed"; }
[ ! -e "$fake/calls" ] || fail "the warm run called: $(cat "$fake/calls")"
[ ! -s "$tmp/warm.err" ] || fail "the warm run printed on stderr: $(cat "$tmp/warm.err")"
changed=$(find "$cache" -newer "$tmp/before-warm" | head -n 5)
[ -z "$changed" ] || fail "the warm run wrote in the cache: $changed"
same_json out-warm out-interp
step "warm run: no cargo, no rustc, nothing written, same JSON"

# 4. Nothing in the cache (but cargo's target directory) names an absolute path of ours.
for dir in "$cache/crates" "$cache/runtime"; do
    if grep -rlF -e "$tmp" -e "$repo" "$dir"; then fail "absolute paths in $dir"; fi
done
step "no absolute path in the cached crates and runtime"

# 5. Warm compiled run against the interpreter, whole process.
median_ms() { # ARGS...: the median wall time of 5 runs, in milliseconds
    local times=() t0 t1 i
    for i in 1 2 3 4 5; do
        t0=$(date +%s%N)
        "$reachc" "$@" >/dev/null 2>&1 || fail "reachc $* failed"
        t1=$(date +%s%N)
        times+=($(((t1 - t0) / 1000000)))
    done
    printf '%s\n' "${times[@]}" | sort -n | sed -n 3p
}
compiled_ms=$(median_ms run pendulum.sde -o out-time)
interp_ms=$(median_ms run --backend interp pendulum.sde -o out-time)
step "warm run of specs/pendulum.sde, median of 5: compiled ${compiled_ms} ms, interp ${interp_ms} ms"

step "passed in $(($(date +%s) - start)) s"
