# Sourced by the CLI tests. Counts in the caller's `passed` and `fail`; `out` is its output folder.

# start_cli_test BUILD_DIR SOURCE_DIR OUT_DIR: sets `build`, `src` (absolute), `bin` (the tools),
# `out` (emptied, absolute) and the counts.
start_cli_test() {
  build=$(cd "$1" && pwd) src=$(cd "$2" && pwd) bin=$build/apps
  rm -rf "$3" && mkdir -p "$3" && out=$(cd "$3" && pwd)
  fail=0 passed=0
}

# expect CODE PATTERN OUTPUT -- command...: the command exits CODE with one "Error:" line on
# stderr that matches PATTERN, leaves no OUTPUT file ("" for none), and no temporary file in $out.
expect() {
  local code=$1 pattern=$2 output=$3
  shift 4
  local err
  err=$("$@" 2>&1 >/dev/null)
  local got=$?
  local lines
  lines=$(grep -c '^Error:' <<<"$err" || true)  # 0 lines: grep's exit 1 is no failure here
  if [ "$got" != "$code" ] || ! grep -q -- "$pattern" <<<"$err" || [ "$lines" != 1 ] ||
     { [ -n "$output" ] && [ -e "$output" ]; }; then
    echo "FAIL: $* -> exit $got (want $code), stderr: $err"
    fail=$((fail + 1))
  else
    passed=$((passed + 1))
  fi
  if grep -q '\.tmp\.' <<<"$(ls -a "$out")"; then echo "FAIL: temp file left by $*"; fail=$((fail + 1)); fi
}

# check MESSAGE COMMAND...: the command succeeds (a script may define its own check first).
declare -F check >/dev/null || check() {
  local msg=$1
  shift
  if "$@"; then passed=$((passed + 1)); else echo "FAIL: $msg"; fail=$((fail + 1)); fi
}
