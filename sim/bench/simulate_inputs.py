"""A case's simulate stage, ready to run by hand: the case planned with `floesim run -n` and only what its simulate
stage reads (the image, the digitised floes, the hull) built. Shared by the bench scripts that run
floesim-simulate themselves (many starts, or two builds, on the same inputs). Standard library only."""
import os
import re
import subprocess

SIMULATE = re.compile(r'^build (\S+)/sim/results\.h5 \S+/sim/summary\.json: stage (\S+) (\S+) (\S+) \| (\S+)$',
                      re.MULTILINE)


def prepare(floesim, case, out, fail):
    """Plans `case` into `out` with the floesim runner `floesim` and builds the simulate stage's inputs; returns
    (floesim-simulate, floes, hull, simulate config). `fail(message)` is called on any failure (it must not
    return)."""
    proc = subprocess.run([floesim, 'run', case, '--out', out, '-n'], capture_output=True, text=True)
    if proc.returncode != 0:
        fail(f'floesim run -n {case} failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}')
    with open(os.path.join(out, 'build.ninja')) as f:
        m = SIMULATE.search(f.read())
    if not m:
        fail(f'{out}/build.ninja: no simulate stage found (the runner\'s plan changed?)')
    floes, hull, config, exe = m.group(2), m.group(3), m.group(4), m.group(5)
    proc = subprocess.run(['ninja', '-C', out, floes, hull], capture_output=True, text=True)
    if proc.returncode != 0:
        fail(f'building the simulate stage\'s inputs failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}')
    return exe, floes, hull, config
