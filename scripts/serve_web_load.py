#!/usr/bin/env python3
"""The cost of serving browsers (issue #38), measured: the release app under Xvfb serves the P2
bending beam (`hox app --serve-web --measure-secs SECS`) while CONNECTIONS headless Chromium
browsers (scripts/browser_shot.py) open the page one after another, each for --each seconds,
and close it. The app's resident memory (its own process) and its threads' CPU time are sampled
every second; its own frame-rate JSON is printed at the end, with the CPU seconds of its serving
threads, its logging threads and the rest, and the serving threads' share of the app's core.
The app is pinned to CPU 0 and the browsers to CPU 1 (taskset, and every 0.2 s again for the
threads SwiftShader pins elsewhere) so that the browsers' software WebGL does not take the
app's core: what is left is the server's own cost.

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
    try:
        for line in open(f"/proc/{pid}/status"):
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


# The app's threads by what they do (their names, as /proc shows them, cut to 15 characters):
# serving the browsers (Rerun's gRPC server on tokio, its message proxy, the web page's server,
# hox's read-only door) and logging (the recording stream and its batcher, which run whether
# browsers are connected or not); the rest is the app (the UI thread, the simulation's, Mesa's
# llvmpipe rendering threads).
SERVING = ("tokio-rt-worker", "message_proxy_s", "re_web_viewer_s", "hox-read-only-d")
LOGGING = ("RecordingStream", "ChunkBatcher::c")


def keep_browsers_on_cpu_1(done):
    """Chromium's software WebGL (SwiftShader) pins its rasterising threads to CPUs of its own
    choosing (Thread<00> of the GPU process to CPU 0, whatever `taskset` gave the browser), so
    the browsers' rendering ran on the app's core. Every 0.2 s, every thread of every Chromium
    process is put back on CPU 1."""
    while not done.is_set():
        for pid in os.listdir("/proc"):
            if not pid.isdigit():
                continue
            try:
                if b"chromium" not in open(f"/proc/{pid}/cmdline", "rb").read():
                    continue
                for tid in os.listdir(f"/proc/{pid}/task"):
                    if os.sched_getaffinity(int(tid)) != {1}:
                        os.sched_setaffinity(int(tid), {1})
            except OSError:
                continue
        time.sleep(0.2)


def thread_cpu_secs(pid):
    """CPU seconds (user + system) of each of `pid`'s threads, by thread id: (name, seconds)."""
    out = {}
    tick = os.sysconf("SC_CLK_TCK")
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            try:
                stat = open(f"/proc/{pid}/task/{tid}/stat").read()
            except OSError:
                continue
            name = stat[stat.index("(") + 1:stat.rindex(")")]
            fields = stat[stat.rindex(")") + 2:].split()
            out[tid] = (name, (int(fields[11]) + int(fields[12])) / tick)
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
    # the app's own process (not xvfb-run's shell, whose command line names it too)
    name = os.path.basename(hox)[:15]
    hox_pids = [int(p) for p in subprocess.run(["pgrep", "-f", f"{hox} app"], capture_output=True, text=True).stdout.split()
                if open(f"/proc/{p}/comm").read().strip() == name]
    samples = []
    threads = {}
    done = threading.Event()

    def sample():
        while not done.is_set():
            samples.append((time.time(), sum(rss_mb(p) for p in hox_pids)))
            for p in hox_pids:
                threads.update(thread_cpu_secs(p))
            time.sleep(1)

    threading.Thread(target=sample, daemon=True).start()
    threading.Thread(target=keep_browsers_on_cpu_1, args=(done,), daemon=True).start()
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
    cpu = {"serving": 0.0, "logging": 0.0, "app": 0.0}
    for thread_name, secs in threads.values():
        cpu["serving" if thread_name in SERVING else "logging" if thread_name in LOGGING else "app"] += secs
    seconds = measured.get("seconds") or args.secs
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
        # CPU seconds of the app's threads over the run, and the serving threads' share of the
        # one core the app is pinned to: what serving the browsers takes from the app itself
        "cpu_secs": {k: round(v, 2) for k, v in cpu.items()},
        "serving_core_share": round(cpu["serving"] / seconds, 4),
    }))


if __name__ == "__main__":
    main()
