#!/usr/bin/env bash
# The README's steps, in their order, on a clean copy of this checkout, as a user would run them:
# in a copy of the tracked and untracked-but-not-ignored files (no target/,
# no out/), with one target folder for every step,
#   1. the README's set-up command (the code block after its `<!-- setup-command -->` marker), as
#      written: it installs what `ssm` needs and builds target/release/ssm;
#   2. target/release/ssm new halo;
#   3. the build command that `ssm new`'s output says to run next;
#   4. target/release/ssm list, which must list halo;
#   5. the render command `ssm new`'s output gives (its output under out/), which must
#      write halo's visibility image;
#   6. the test command `ssm new`'s output gives (cargo test -p ssm-halo);
#   7. every command of the README's "A short tour of `ssm`" (each backticked `ssm ...`), in
#      order, as written with target/release/ssm for `ssm`, except:
#      - `ssm compare` gets `--width 160 --height 120` appended (at its default 640x480 it takes
#        about 260 s on lavapipe with two cores, 13 s at 160x120);
#      - `ssm view` (a live window, with no one-frame mode) runs as written in a virtual X server
#        (Xvfb, from scripts/install-deps.sh --for-tests) until it prints that it presented its
#        first frame (`ssm view: showing ...`), then is stopped; ssm-bench/tests/view.rs checks
#        what the window shows.
# Each step prints what it runs; the first that fails stops the script, which names it and exits 1.
#
# The copy lives in a temporary folder, removed at the end (SSM_README_STEPS_KEEP=1 keeps it). Its
# target/ is a link to one folder kept between runs, target/readme-steps of this checkout (or
# $SSM_README_STEPS_TARGET), so that the dependencies come from the cache as a user's second
# build's would; the copy's own crates are new files and compile afresh every run. Built-in
# scenes only: no model needs fetching. Run by .ci/run after the README's test command, through
# ssm-bench/tests/readme_steps.rs (an ignored test: `cargo test -p ssm-bench --test readme_steps
# -- --ignored`).
set -euo pipefail
checkout=$(cd "$(dirname "$0")/.." && pwd)
target=${SSM_README_STEPS_TARGET:-$checkout/target/readme-steps}
mkdir -p "$target"
target=$(cd "$target" && pwd)
copy=$(mktemp -d "${TMPDIR:-/tmp}/ssm-readme-steps.XXXXXX")
xvfb_pid=
cleanup() {
    if [ -n "$xvfb_pid" ]; then kill "$xvfb_pid" 2>/dev/null || true; wait "$xvfb_pid" 2>/dev/null || true; fi
    if [ "${SSM_README_STEPS_KEEP:-}" = 1 ]; then echo "readme-steps: the copy is kept at $copy"; else rm -rf "$copy"; fi
}
trap cleanup EXIT

started=$SECONDS
current="copying the checkout"
fail() { echo "readme-steps: FAILED at step $current: $*" >&2; exit 1; }
# `step N "what" command...`: says what it runs, runs it in the copy, stops the script if it fails.
step() {
    current="$1 ($2)"
    shift 2
    echo
    echo "readme-steps: step $current, at $((SECONDS - started)) s: $*"
    (cd "$copy" && "$@" </dev/null) || fail "\`$*\` exited with $?"
}

# The clean copy: what a clone of this working tree would hold. Files deleted from the working tree
# but still in the index are left out (tar --ignore-failed-read); mtimes are the copy's own (-m),
# as a fresh clone's are.
echo "readme-steps: copying $checkout to $copy (target folder $target)"
(cd "$checkout" && git ls-files -z --cached --others --exclude-standard) \
    | (cd "$checkout" && tar --null --files-from=- --ignore-failed-read -cf - 2>/dev/null) \
    | tar -xmf - -C "$copy" || fail "copying the files git lists"
[ -f "$copy/README.md" ] && [ -f "$copy/Cargo.toml" ] || fail "the copy has no README.md or Cargo.toml"
ln -s "$target" "$copy/target"
# The README's `target/release/ssm` is then this folder's, whatever the caller's CARGO_TARGET_DIR.
export CARGO_TARGET_DIR="$copy/target"
ssm=target/release/ssm
# Mesa's loader looks for a Wayland socket; headless runs have none (as in scripts/test.sh).
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
readme="$copy/README.md"

# 1. The set-up command: the first line of the code block after the `<!-- setup-command -->` marker.
current="1 (reading the set-up command from README.md)"
setup=$(awk '/<!-- setup-command -->/ { found = 1; next }
    found && /^```/ { fence++; next } found && fence == 1 && NF { print; exit }' "$readme")
[ -n "$setup" ] || fail "no code block after the <!-- setup-command --> marker in README.md"
step 1 "the README's set-up command" bash -c "$setup"

# 2. `ssm new halo`, and the commands its output says to run next (indented lines after "Next, in").
step 2 "ssm new halo" sh -c "$ssm new halo > new-output.txt"
cat "$copy/new-output.txt"
current="2 (reading ssm new's next steps)"
next=$(awk '/Next, in / { found = 1; next } found && /^  / { sub(/^ +/, ""); sub(/  +\(.*\)$/, ""); print; next } found { exit }' "$copy/new-output.txt")
build=$(grep -m1 '^cargo build' <<<"$next" || true)
render=$(grep -m1 "^$ssm render " <<<"$next" || true)
test=$(grep -m1 '^cargo test' <<<"$next" || true)
[ -n "$build" ] && [ -n "$render" ] && [ -n "$test" ] \
    || fail "expected a cargo build, a $ssm render and a cargo test line after \"Next, in\" in ssm new's output, got:
$next"

# 3. The build it asks for.
step 3 "the build ssm new's output asks for" bash -c "$build"

# 4. The technique is listed.
step 4 "ssm list shows halo" sh -c "$ssm list > list-output.txt"
grep -q '^halo: ' "$copy/list-output.txt" || fail "no \`halo: \` line in \`$ssm list\`'s output"

# 5. Its render command, as it says (its output under out/, inside the copy).
step 5 "the render ssm new's output gives" bash -c "$render"
[ -f "$copy/out/halo/halo/visibility.png" ] || fail "no out/halo/halo/visibility.png"

# 6. Its test.
step 6 "the test ssm new's output gives" bash -c "$test"

# 7. The tour: every backticked `ssm ...` of its section, in order.
current="7 (reading the tour from README.md)"
tour=$(awk '/^## A short tour of `ssm`/ { found = 1; next } found && /^## / { exit } found' "$readme" \
    | tr '\n' ' ' | grep -o '`ssm [^`]*`' | tr -d '`' | sed -E 's/ +/ /g')
[ -n "$tour" ] || fail "no \`ssm ...\` commands in README.md's \"A short tour of \`ssm\`\""
n=0
while IFS= read -r -u 3 command; do
    n=$((n + 1))
    run="$ssm ${command#ssm }"
    case "$command" in
    "ssm compare "*)
        step "7.$n" "tour: $command" bash -c "$run --width 160 --height 120"
        ;;
    "ssm view "*)
        # Until its first frame is presented, in a virtual X server on a free display.
        current="7.$n (tour: $command)"
        command -v Xvfb >/dev/null || fail "Xvfb is missing: scripts/install-deps.sh --for-tests installs it"
        display=$(for d in $(seq 90 400); do [ -e "/tmp/.X11-unix/X$d" ] || [ -e "/tmp/.X$d-lock" ] || { echo "$d"; break; }; done)
        Xvfb ":$display" -screen 0 1024x768x24 -nolisten tcp >/dev/null 2>&1 &
        xvfb_pid=$!
        for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X$display" ] && break; sleep 0.1; done
        [ -e "/tmp/.X11-unix/X$display" ] || fail "Xvfb did not open :$display"
        echo
        echo "readme-steps: step $current, at $((SECONDS - started)) s: DISPLAY=:$display $run (until its first frame)"
        (cd "$copy" && DISPLAY=":$display" WAYLAND_DISPLAY='' exec bash -c "exec $run" </dev/null > view-output.txt 2> view-stderr.txt) &
        view_pid=$!
        for _ in $(seq 1200); do
            grep -q '^ssm view: showing ' "$copy/view-output.txt" 2>/dev/null && break
            kill -0 "$view_pid" 2>/dev/null || break
            sleep 0.1
        done
        shown=$(grep -m1 '^ssm view: showing ' "$copy/view-output.txt" 2>/dev/null || true)
        kill "$view_pid" 2>/dev/null || true
        wait "$view_pid" 2>/dev/null || true
        kill "$xvfb_pid" 2>/dev/null || true
        wait "$xvfb_pid" 2>/dev/null || true
        xvfb_pid=
        cat "$copy/view-output.txt"
        [ -n "$shown" ] || fail "no first frame within 120 s; its stderr:
$(cat "$copy/view-stderr.txt")"
        ;;
    *)
        step "7.$n" "tour: $command" bash -c "$run"
        ;;
    esac
done 3<<<"$tour"

echo
echo "readme-steps: all steps passed in $((SECONDS - started)) s"
