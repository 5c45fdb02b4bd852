# Shared by the end-to-end scripts in tests/apps: a scratch folder removed on exit, pass/fail
# counters, and the summary line whose exit status is the test's result.
#   source "$(dirname "$0")/lib.sh"   ...   finish
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passes=0
pass() { passes=$((passes + 1)); echo "ok   $1"; }
fail() { failures=$((failures + 1)); echo "FAIL $1"; }
finish() { echo "$passes passed, $failures failed"; [[ $failures -eq 0 ]]; }
