#!/usr/bin/env bash
# Lists every line of a tracked file that names a path outside the repository: the folder beside a
# checkout (the steering's shared/ folder of reference data) or a folder of one machine (/work/..., /root/...,
# /home/...). A user's clone has neither. Exit 0 when there is none, 1 (with the lines) otherwise.
# .ci/run runs it before the tests.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
pattern='(\.\./)+shared\b|(^|[^A-Za-z0-9_.~-])/(work|root|home)/'
if git grep -nIE "$pattern" -- . ':!scripts/check-paths.sh'; then
  exit 1
fi
exit 0
