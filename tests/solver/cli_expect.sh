#!/usr/bin/env bash
# cli_expect.sh ok|fail|ok_without REGEX [FILE-CHECK] -- command ...
# Runs the command; passes when the exit status is as expected (fail = non-zero) and the combined
# output matches REGEX (extended grep); ok_without: exit status 0 and no line matches REGEX. Used by the
# basalt-run end-to-end tests.
set -u
want=$1; regex=$2; shift 2
[ "$1" = "--" ] && shift
out=$("$@" 2>&1); code=$?
echo "$out"
if [ "$want" = ok_without ]; then
  if [ $code -ne 0 ]; then echo "cli_expect: exit status $code, expected 0"; exit 1; fi
  if grep -Eq -- "$regex" <<<"$out"; then echo "cli_expect: output matches /$regex/, expected not to"; exit 1; fi
  exit 0
fi
if [ "$want" = ok ] && [ $code -ne 0 ]; then echo "cli_expect: exit status $code, expected 0"; exit 1; fi
if [ "$want" = fail ] && [ $code -eq 0 ]; then echo "cli_expect: exit status 0, expected an error"; exit 1; fi
if ! grep -Eq -- "$regex" <<<"$out"; then echo "cli_expect: output does not match /$regex/"; exit 1; fi
exit 0
