#!/usr/bin/env bash
# The C API from a C program against the C++ header (runtime-demo): the same blend, line for
# line, in the split layout, in xyzr, and as a local blend with those weights at every site.
# usage: bindings.sh BUILD_DIR FILE.spx
set -euo pipefail
build=$1 spx=$2
fail=0 passed=0
for weights in "1 0 0 0 0" "0 0 1 0 0" "0.5 0.25 0 0.25 0" "0.1 0.2 0.3 0.2 0.2" "2 -1 0 0 1"; do
  # shellcheck disable=SC2086
  demo=$("$build/samples/runtime-demo" "$spx" $weights)
  # shellcheck disable=SC2086
  c=$("$build/tests/c_api_check" "$spx" $weights)
  header=$(printf '%s\n' "$demo" | grep '^#')
  body=$(printf '%s\n' "$demo" | grep -v '^#')
  expected=$(printf '%s\n%s\n%s\n%s\n' "$header" "$body" "$body" "$body")
  if [ "$c" = "$expected" ]; then passed=$((passed + 1)); else echo "FAIL: C API differs from the header at weights $weights"; fail=$((fail + 1)); fi
done
# The morph blend (one weight per example after the rest): split layout and xyzr.
for weights in "0 0 0 0" "1 0 0 0" "1 1 0 0" "0.5 -0.25 1.5 2"; do
  # shellcheck disable=SC2086
  demo=$("$build/samples/runtime-demo" "$spx" --morph $weights)
  # shellcheck disable=SC2086
  c=$("$build/tests/c_api_check" "$spx" --morph $weights)
  header=$(printf '%s\n' "$demo" | grep '^#')
  body=$(printf '%s\n' "$demo" | grep -v '^#')
  expected=$(printf '%s\n%s\n%s\n' "$header" "$body" "$body")
  if [ "$c" = "$expected" ]; then passed=$((passed + 1)); else echo "FAIL: C API's morph blend differs from the header at $weights"; fail=$((fail + 1)); fi
done
if "$build/tests/c_api_check" "$spx" --morph 1 0 0 0 0 2>/dev/null; then
  echo "FAIL: a morph blend given the rest's weight too must fail"; fail=$((fail + 1))
else passed=$((passed + 1)); fi
echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
