#!/usr/bin/env bash
# Fails when a source file outside tests has more than 700 lines (issue #34: each file one job;
# the rooms grew back past this size once because nothing checked it). Test files — `tests.rs`,
# `*_tests.rs`, `testing.rs` and anything under a `tests/` or `benches/` folder — are not counted.
# Usage: bash scripts/check-sizes.sh [LIMIT]
set -euo pipefail
cd "$(dirname "$0")/.."
limit="${1:-700}"
over=0
while IFS= read -r file; do
    case "$file" in
        */tests/*|*/benches/*|*/tests.rs|*_tests.rs|*/testing.rs) continue ;;
    esac
    lines=$(wc -l < "$file")
    if [ "$lines" -gt "$limit" ]; then
        echo "check-sizes: $file has $lines lines (limit $limit): split it, one job per file" >&2
        over=$((over + 1))
    fi
done < <(git ls-files --cached --others --exclude-standard '*.rs')
if [ "$over" -gt 0 ]; then
    echo "check-sizes: $over source file(s) over $limit lines" >&2
    exit 1
fi
echo "check-sizes: every source file outside tests has at most $limit lines"
