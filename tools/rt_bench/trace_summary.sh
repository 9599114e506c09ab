#!/bin/sh
# trace_summary.sh TRACE.csv [WINDOW] [RATE_HZ]: what a per-frame trace (sonocomp --trace)
# says about its slow frames: the frame time's mean, p50 and p99; the means of consecutive
# windows of WINDOW frames (default 30), lowest and highest; and where the slowest 1 % of the
# frames fall, in seconds from the start (frame / RATE_HZ, default 60) and by tenth of the run.
# Slow frames bunched at one phase of a repeating probe script point at the content; spread
# over the run, or in a stretch that does not repeat, at the host (docs/performance.md, the
# twenty-second pass). POSIX sh and awk only.
set -eu
[ $# -ge 1 ] || { echo "usage: trace_summary.sh TRACE.csv [WINDOW] [RATE_HZ]" >&2; exit 2; }
TRACE=$1
WINDOW=${2:-30}
RATE=${3:-60}
[ -r "$TRACE" ] || { echo "trace_summary: cannot read $TRACE" >&2; exit 1; }
case $WINDOW in '' | *[!0-9]*) echo "trace_summary: WINDOW $WINDOW: expected frames" >&2; exit 2;; esac
case $RATE in '' | *[!0-9]*) echo "trace_summary: RATE_HZ $RATE: expected Hz" >&2; exit 2;; esac
if [ "$WINDOW" -lt 1 ] || [ "$RATE" -lt 1 ]; then
    echo "trace_summary: WINDOW and RATE_HZ at least 1" >&2
    exit 2
fi
awk -F, -v W="$WINDOW" -v R="$RATE" '
# nearest rank: the smallest value with at least p of the frames at or under it
function rank(p, n,    r) { r = int(p * n); if (r < p * n) r++; return r < 1 ? 1 : r }
NR == 1 {
    for (i = 1; i <= NF; i++) { if ($i == "frame_us") col = i; if ($i == "frame") fcol = i }
    if (!col || !fcol) { print "trace_summary: no frame / frame_us column" > "/dev/stderr"; bad = 1; exit 1 }
    next
}
$col ~ /^[0-9]+$/ && $fcol ~ /^[0-9]+$/ { n++; t[n] = $col; fr[n] = $fcol; sum += $col; next }
{ rejected++ }
END {
    if (bad) exit 1
    if (n == 0) { print "trace_summary: no frames" > "/dev/stderr"; exit 1 }
    # the frame times sorted (POSIX awk has no sort: a shell sort of a copy)
    for (i = 1; i <= n; i++) s[i] = t[i]
    for (gap = int(n / 2); gap > 0; gap = int(gap / 2))
        for (i = gap + 1; i <= n; i++) {
            v = s[i]; j = i
            while (j > gap && s[j - gap] > v) { s[j] = s[j - gap]; j -= gap }
            s[j] = v
        }
    p50 = s[rank(0.50, n)]; p99 = s[rank(0.99, n)]
    printf "trace %d frames: frame mean %.3f ms, p50 %.3f, p99 %.3f, worst %.3f", n, sum / n / 1000, p50 / 1000, p99 / 1000, s[n] / 1000
    if (rejected) printf " (%d malformed rows skipped)", rejected
    printf "\n"
    lo = -1; hi = -1
    for (i = 1; i + W - 1 <= n; i += W) {
        m = 0; for (j = i; j < i + W; j++) m += t[j]; m /= W
        if (lo < 0 || m < lo) { lo = m; lo_at = fr[i] }
        if (hi < 0 || m > hi) { hi = m; hi_at = fr[i] }
    }
    if (lo >= 0)
        printf "windows of %d frames: mean %.3f ms (from %.1f s) to %.3f ms (from %.1f s)\n", W, lo / 1000, lo_at / R, hi / 1000, hi_at / R
    k = int(n / 100); if (k < 1) k = 1
    cut = s[n - k + 1]
    for (b = 0; b < 10; b++) tenth[b] = 0
    line = ""; shown = 0; c = 0
    for (i = 1; i <= n && c < k; i++) if (t[i] >= cut) {
        c++; b = int((i - 1) * 10 / n); tenth[b]++
        if (shown < 20) { line = line sprintf(" %.2f", fr[i] / R); shown++ }
    }
    printf "slowest 1 %% (%d frames, %.3f ms and up) at s:%s%s\n", c, cut / 1000, line, (c > shown ? " ..." : "")
    printf "  by tenth of the run:"
    for (b = 0; b < 10; b++) printf " %d", tenth[b]
    printf "\n"
}' "$TRACE"
