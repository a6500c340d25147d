#!/usr/bin/env python3
"""The cost of serving browsers (issue #38), measured: the release app under Xvfb serves the P2
bending beam (`hox app --serve-web --measure-secs SECS`) while CONNECTIONS headless Chromium
browsers (scripts/browser_shot.py) open the page one after another, each for --each seconds,
and close it. The app's resident memory is sampled every second; its own frame-rate JSON is
printed at the end. The app is pinned to CPU 0 and the browsers to CPU 1 (taskset) so that the
browsers' software WebGL does not take the app's core: what is left is the server's own cost.

    scripts/serve_web_load.py [--secs 150] [--connections 10] [--each 8] [--history-mb 64] [--hox BIN]

Run it twice, with --connections 0 and 10, and compare (docs/WEB.md)."""

import argparse
import json
import os
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rss_mb(pid):
    total = 0
    for p in [pid] + children(pid):
        try:
            for line in open(f"/proc/{p}/status"):
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1]) / 1024
        except OSError:
            pass
    return total


def children(pid):
    out = []
    try:
        for c in open(f"/proc/{pid}/task/{pid}/children").read().split():
            out.append(int(c))
            out += children(int(c))
    except OSError:
        pass
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--secs", type=float, default=150)
    ap.add_argument("--connections", type=int, default=10)
    ap.add_argument("--each", type=float, default=8)
    ap.add_argument("--history-mb", type=int, default=64)
    ap.add_argument("--hox", help="the hox binary (default: the release build in CARGO_TARGET_DIR), "
                    "to compare two builds side by side")
    args = ap.parse_args()
    target = os.environ.get("CARGO_TARGET_DIR", os.path.expanduser("~/.cache/hox-target"))
    hox = args.hox or os.path.join(target, "release", "hox")
    home = f"/tmp/hox-load-home-{os.getpid()}"
    os.makedirs(home, exist_ok=True)
    app = subprocess.Popen(
        ["taskset", "-c", "0", "xvfb-run", "-a", "-s", "-screen 0 1600x900x24", "env", f"HOME={home}", hox, "app",
         "--fresh", "--scene", "bending", "--play", "--serve-web", "--web-port", "0", "--grpc-port", "0",
         "--history-mb", str(args.history_mb), "--size", "1280x720", "--measure-secs", str(args.secs)],
        stdout=subprocess.PIPE, text=True)
    url = app.stdout.readline().strip()
    print(f"serving at {url}", file=sys.stderr)
    time.sleep(1)
    hox_pids = [int(p) for p in subprocess.run(["pgrep", "-f", f"{hox} app"], capture_output=True, text=True).stdout.split()]
    samples = []
    done = threading.Event()

    def sample():
        while not done.is_set():
            samples.append((time.time(), sum(rss_mb(p) for p in hox_pids)))
            time.sleep(1)

    threading.Thread(target=sample, daemon=True).start()
    opened = 0
    for k in range(args.connections):
        if app.poll() is not None:
            break
        subprocess.run(["taskset", "-c", "1", "python3", os.path.join(ROOT, "scripts/browser_shot.py"), url,
                        f"/tmp/hox-load-{os.getpid()}-{k}.png", "--wait", str(args.each), "--shots", "0"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=300)
        opened += 1
        print(f"connection {k + 1} opened and closed, app resident {samples[-1][1]:.0f} MB", file=sys.stderr)
    result = app.stdout.read()
    app.wait()
    done.set()
    measured = json.loads(result.strip().splitlines()[-1]) if result.strip() else {}
    rss = [s[1] for s in samples if s[1] > 0]
    print(json.dumps({
        "connections": opened,
        "history_mb": args.history_mb,
        "display_fps": measured.get("display_fps"),
        "sim_frames": measured.get("sim_frames"),
        "sim_ms_per_frame": measured.get("sim_ms_per_frame"),
        "rss_mb_first": rss[0] if rss else None,
        "rss_mb_peak": max(rss) if rss else None,
        "rss_mb_last": rss[-1] if rss else None,
        "seconds": measured.get("seconds"),
    }))


if __name__ == "__main__":
    main()
