#!/usr/bin/env bash
# Mutation check (issue 23): applies each listed source mutation to a scratch copy of this
# checkout and checks that at least one test fails; see tests/mutation.py for the options.
# Usage: tests/mutation.sh [--cargo "ARGS"] [--no-pytest] [--list] [radius prestress kn cable taut curvature dx-seed]
# Slow (one release build per mutation): not part of CI.
set -euo pipefail
exec python3 "$(dirname "$0")/mutation.py" "$@"
