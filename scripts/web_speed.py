#!/usr/bin/env python3
"""How fast the simulation runs in a student's browser (issue #59): milliseconds per simulated
frame of the paper's P1 1,280 and P2 160 bending beams in the page (the app compiled to
WebAssembly, one thread, the colour sweep on two-lane simd128 batches) against the native
binary on one thread (`hox bench --threads 1 --sweep colour`), measured side by side: the page
and the desktop take turns, round after round, and each row's figure is the median over rounds;
then how soon the page shows the beam coloured (browser_shot.py --frames, the first frame with
the beam in the field's colours), how many simulated frames per real second the page steps
while it plays P2 bending (its published state read twice, ten seconds apart) and the size of
its module.

    python3 scripts/web_speed.py [--site DIR] [--frames 60] [--rounds 3] [--hox BIN]

Prints the machine line and a markdown table (docs/WEB.md quotes it; `python3
scripts/docs_tables.py docs/WEB.md` writes it in). The site is built by scripts/build-web.sh
(default: site/ in the repository); the page runs in headless Chromium (scripts/setup.sh), its
benchmark called through the module's `bench_beam` (gui/platform/page.rs). `hox` is --hox, else
$HOX_BIN, else the release binary under $CARGO_TARGET_DIR.
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import first_coloured_frame  # noqa: E402
from hox_binary import hox_binary  # noqa: E402
from web_figures import machine  # noqa: E402

BEAMS = [("P1 16x4x4 r1", "P1 1,280 tets"), ("P2 8x2x2", "P2 160 tets")]
ASKED = 2.5


def page_ms(url, label, frames, scratch):
    """The page's median ms per frame of `label`."""
    state = scratch / "state.json"
    expression = f"window.hox.bench_beam({json.dumps(label)}, {frames})"
    subprocess.run(
        [sys.executable, str(ROOT / "scripts/browser_shot.py"), url + "?scene=bending", str(scratch / "page.png"),
         "--wait", "8", "--state", str(state), "--eval", expression],
        check=True, stdout=subprocess.DEVNULL)
    result = json.loads(state.read_text())
    if result.get("eval_error") or not result.get("eval"):
        sys.exit(f"web_speed: the page's benchmark failed: {result.get('eval_error')}")
    return json.loads(result["eval"])


def first_coloured(url, scratch, wait=30):
    """Seconds from asking for the page (P2 bending, playing) to its first frame with the beam
    coloured (over 3 % of the app's view, app/tests/page.rs's rule), or None."""
    frames = scratch / "frames"
    frames.mkdir()
    subprocess.run([sys.executable, str(ROOT / "scripts/browser_shot.py"), url + "?scene=bending&play",
                    str(scratch / "first.png"), "--wait", str(wait), "--frames", str(frames)],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for png in sorted(frames.glob("frame-*.png"), key=lambda p: float(p.stem[len("frame-"):])):
        if first_coloured_frame.coloured_share(str(png), first_coloured_frame.APP_VIEW) > 0.03:
            return float(png.stem[len("frame-"):])
    return None


PLAYED_SECS = 10

# Two readings of the page's published state PLAYED_SECS apart: simulated frames stepped and
# simulated seconds advanced per real second while the page plays.
PLAY_RATE = """new Promise(done => {
  const read = () => JSON.parse(window.hox_state);
  const a = read(), t0 = performance.now();
  setTimeout(() => {
    const b = read(), secs = (performance.now() - t0) / 1000;
    done(JSON.stringify({
      frames_per_sec: (b.frames_stepped - a.frames_stepped) / secs,
      sim_secs_per_sec: (b.configurations[0].time_secs - a.configurations[0].time_secs) / secs,
      element: b.configurations[0].element,
      ms_per_frame: b.configurations[0].ms_per_frame,
    }));
  }, %d);
})""" % (PLAYED_SECS * 1000)


def play_rate(url, scratch):
    """Simulated frames per real second while the page plays P2 bending (its frames are 1/60 s)."""
    state = scratch / "play.json"
    subprocess.run(
        [sys.executable, str(ROOT / "scripts/browser_shot.py"), url + "?scene=bending&element=p2&play",
         str(scratch / "play.png"), "--wait", "5", "--state", str(state), "--eval", PLAY_RATE],
        check=True, stdout=subprocess.DEVNULL)
    result = json.loads(state.read_text())
    if result.get("eval_error") or not result.get("eval"):
        sys.exit(f"web_speed: the page's play rate could not be read: {result.get('eval_error')}")
    return json.loads(result["eval"])


def native_ms(hox, label, frames):
    """The native binary's median ms per frame of `label`, one thread, the colour sweep."""
    out = subprocess.run([hox, "bench", "--only", label, "--threads", "1", "--sweep", "colour",
                          "--frames", str(frames)], check=True, capture_output=True, text=True).stdout
    rows = [line.split("|")[1:-1] for line in out.splitlines() if line.startswith("|")]
    header = [c.strip() for c in rows[0]]
    at = header.index("ours ms/frame")
    for row in rows[2:]:
        if row[0].strip().lower() == label.lower():
            return float(row[at].strip().strip("*"))
    sys.exit(f"web_speed: no row {label!r} in hox bench's table:\n{out}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--site", default=str(ROOT / "site"))
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--hox")
    args = ap.parse_args()
    hox = hox_binary(args.hox)
    server = subprocess.Popen([hox, "serve-app", "--site", args.site, "--web-port", "0", "--seconds", "3600"],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        url = server.stdout.readline().strip()
        if not url.startswith("http://"):
            sys.exit(f"web_speed: hox serve-app printed no address (is {args.site} a built site?)")
        page = {label: [] for label, _ in BEAMS}
        native = {label: [] for label, _ in BEAMS}
        lanes = {}
        with tempfile.TemporaryDirectory(prefix="hox-web-speed-") as tmp:
            first = first_coloured(url, Path(tmp))
            played = play_rate(url, Path(tmp))
            for r in range(args.rounds):
                for label, _ in BEAMS:
                    # the order alternates, so that neither always goes first
                    first_page = r % 2 == 0
                    for side in ([0, 1] if first_page else [1, 0]):
                        if side == 0:
                            result = page_ms(url, label, args.frames, Path(tmp))
                            page[label].append(result["ms_per_frame"])
                            lanes[label] = result["lanes"]
                        else:
                            native[label].append(native_ms(hox, label, args.frames))
        print(machine())
        print()
        print("| beam | in the page (Chromium, one thread) | native, one thread | page / native | asked |")
        print("|---|---|---|---|---|")
        for label, name in BEAMS:
            p, n = statistics.median(page[label]), statistics.median(native[label])
            width = f", {lanes[label]} lanes" if lanes.get(label) else ""
            print(f"| {name} ({label}) | {p:.2f} ms{width} | {n:.2f} ms | **{p / n:.2f}×** | ≤ {ASKED}× |")
        site = Path(args.site)
        wasm, gz = (site / "hox_bg.wasm").stat().st_size / 1e6, (site / "hox_bg.wasm.gz").stat().st_size / 1e6
        coloured = f"**{first:.1f} s**" if first is not None else "never within 30 s"
        print()
        print("| the page | now | asked |")
        print("|---|---|---|")
        print(f"| first coloured frame after the page was asked for (P2 bending, playing) | {coloured} | 10 s |")
        print(f"| P2 bending playing in the page ({played['element']}, frames of 1/60 s) | "
              f"**{played['frames_per_sec']:.0f} simulated frames/s** "
              f"({played['sim_secs_per_sec']:.2f} simulated s per s) | 60 |")
        print(f"| hox_bg.wasm | {wasm:.1f} MB, {gz:.1f} MB gzipped (as `hox serve-app` sends it) | 20 MB, 6 MB compressed |")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
