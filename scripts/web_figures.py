#!/usr/bin/env python3
"""docs/WEB.md's table of today, measured (issue #58: a document's figures are a command's
output): how soon a student's browser shows the body coloured, what serving browsers costs the
app, the data a browser receives and the binary's size, on this machine.

    python3 scripts/web_figures.py [--quick] [--hox BIN]

Prints the machine line and a markdown table (`python3 scripts/docs_tables.py docs/WEB.md`
writes it into docs/WEB.md; `cargo test -p hox --test web -- --ignored` checks that the
committed table keeps this format). Needs headless Chromium and Xvfb (scripts/setup.sh).
`hox` is --hox, else $HOX_BIN, else the release binary under $CARGO_TARGET_DIR.

- **First coloured frame**: a server started (the live app under Xvfb, `hox serve` of a 0.5 s
  recording, `hox lesson why-high-order --serve-web`), its address opened in headless Chromium
  with software WebGL (scripts/browser_shot.py --frames), and the first frame whose 3D view is
  over 5 % in the field's colours (scripts/first_coloured_frame.py: app/tests/web.rs's rule).
- **Serving's cost**: scripts/serve_web_load.py twice, without browsers and with browsers opened
  and closed one after another, the app pinned to one core and the browsers to the other: the
  app's frame rate, its serving threads' CPU time and its resident memory.
- **Data per browser**: the bytes of a recording of the P2 bending beam (`hox record`), per
  second of simulation, at the 30 frames a second the app serves (`--serve-fps 30`).

--quick (the format check) waits and measures for a few seconds only.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import first_coloured_frame  # noqa: E402
from hox_binary import hox_binary  # noqa: E402


def machine() -> str:
    """The CPU and core count, as `hox bench` names them."""
    cpu = os.uname().machine
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f'Machine: "{cpu}", {os.cpu_count()} logical cores.'


def first_coloured(command, wait, scratch, name):
    """Seconds from asking for the page to its first frame with the body coloured, or None."""
    frames = scratch / f"frames-{name}"
    frames.mkdir()
    server = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                              start_new_session=True, cwd=scratch)
    try:
        url = server.stdout.readline().strip()
        if not url.startswith("http://"):
            sys.exit(f"web_figures: `{' '.join(command)}` printed no address: {url!r}")
        shot = subprocess.run([sys.executable, str(ROOT / "scripts/browser_shot.py"), url, str(scratch / f"{name}.png"),
                               "--wait", str(wait), "--frames", str(frames)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=wait + 120)
        if shot.returncode != 0:
            sys.exit(f"web_figures: browser_shot.py failed on {url}")
    finally:
        os.killpg(server.pid, 15)
        server.wait()
    for png in sorted(frames.glob("frame-*.png"), key=lambda p: float(p.stem[len("frame-"):])):
        if first_coloured_frame.coloured_share(str(png)) > 0.05:
            return float(png.stem[len("frame-"):])
    return None


def load(hox, secs, connections, each):
    out = subprocess.run([sys.executable, str(ROOT / "scripts/serve_web_load.py"), "--hox", hox, "--secs", str(secs),
                          "--connections", str(connections), "--each", str(each)],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def seconds(value, wait):
    return f"**{value:.1f} s**" if value is not None else f"never within {wait:.0f} s"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a few seconds per measurement: the format check")
    ap.add_argument("--hox", help="the hox binary (default: $HOX_BIN, else the release build)")
    args = ap.parse_args()
    hox = hox_binary(args.hox)
    if not any(shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")):
        sys.exit("web_figures: no Chromium (scripts/setup.sh installs Debian's)")
    wait = 25 if args.quick else 30
    secs, connections, each = (24, 2, 6) if args.quick else (150, 10, 10)
    scratch = Path(tempfile.mkdtemp(prefix="hox-web-figures-"))
    home = scratch / "home"
    home.mkdir()
    xvfb = ["xvfb-run", "-a", "-s", "-screen 0 1600x900x24", "env", f"HOME={home}"]
    ports = ["--web-port", "0", "--grpc-port", "0"]

    live = first_coloured(xvfb + [hox, "app", "--fresh", "--scene", "bending", "--play", "--serve-web", "--serve-fps", "30",
                                  "--size", "1280x720"] + ports, wait, scratch, "app")
    print(f"live app: {live}", file=sys.stderr)
    recording = scratch / "bending.rrd"
    subprocess.run([hox, "record", "--scene", "bending", "--seconds", "0.5", "--out", str(recording)], check=True,
                   capture_output=True)
    served = first_coloured([hox, "serve", str(recording)] + ports, wait, scratch, "serve")
    print(f"hox serve: {served}", file=sys.stderr)
    lesson = first_coloured([hox, "lesson", "why-high-order", "--serve-web"] + ports, wait, scratch, "lesson")
    print(f"lesson: {lesson}", file=sys.stderr)

    # the browsers' cost: without and with them, one after the other in one run
    quiet = load(hox, secs, 0, each)
    busy = load(hox, secs, connections, each)
    print(f"load: {quiet} / {busy}", file=sys.stderr)

    two_secs = scratch / "two.rrd"
    subprocess.run([hox, "record", "--scene", "bending", "--seconds", "2", "--out", str(two_secs)], check=True,
                   capture_output=True)
    mbit_per_browser = two_secs.stat().st_size * 8 / 1e6 / 2 * (30 / 60)
    binary_mb = Path(hox).stat().st_size / 1e6

    def fps(r):
        return r["display_fps"] or 0.0

    change = 100 * (fps(busy) / fps(quiet) - 1) if fps(quiet) else float("nan")
    memory = "{:.0f} → {:.0f} → {:.0f} MB"
    print(machine())
    print()
    print("| what | now | side by side | asked |")
    print("|---|---|---|---|")
    print(f"| first coloured frame, the live app (P2 bending, playing, `--serve-fps 30`) | {seconds(live, wait)} | | 10 s |")
    print(f"| first coloured frame, `hox serve` of a 0.5 s recording | {seconds(served, wait)} | | 10 s |")
    print(f"| first coloured frame, `hox lesson why-high-order --serve-web` | {seconds(lesson, wait)} | | 10 s |")
    print(f"| the app's frame rate, {busy['connections']} browsers opened and closed ({each} s each, {secs} s) "
          f"| {fps(busy):.1f} fps | no browser: {fps(quiet):.1f} fps (**{change:+.1f} %**) | within 10 % |")
    print(f"| CPU of the serving threads in those {secs} s | {busy['cpu_secs']['serving']:.2f} s "
          f"({100 * busy['serving_core_share']:.1f} % of the core) | no browser: {quiet['cpu_secs']['serving']:.2f} s | |")
    print(f"| the app's resident memory, start → peak → end "
          f"| {memory.format(busy['rss_mb_first'], busy['rss_mb_peak'], busy['rss_mb_last'])} "
          f"| no browser: {memory.format(quiet['rss_mb_first'], quiet['rss_mb_peak'], quiet['rss_mb_last'])} "
          f"| history bound 64 MB |")
    print(f"| data per browser, the P2 beam at 30 frames a second | {mbit_per_browser:.1f} Mbit/s "
          f"| thirty browsers: {30 * mbit_per_browser:.0f} Mbit/s | |")
    print(f"| the hox binary (release, the web viewer inside) | {binary_mb:.0f} MB | | |")
    shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
