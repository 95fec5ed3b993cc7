"""What floesim-simulate prints as it runs, read back by the bench scripts: its progress lines (one per tenth of
the run) and its closing line of steps, wall time and speed. Standard library only."""
import re

PROGRESS = re.compile(r't = ([0-9.]+) s\s+\(\s*([0-9]+) %, ([0-9.]+) s wall, awake floes ([0-9]+), contacts ([0-9]+)\)')
TOTAL = re.compile(r'steps ([0-9]+), wall ([0-9.]+) s, ([0-9.]+) ms/step, ([0-9.]+) simulated s per wall s')
PEAK = re.compile(r'^peak memory ([0-9.]+) MB$', re.MULTILINE)
AWAKE = re.compile(r'^mean awake floes ([0-9.]+)[ ,]', re.MULTILINE)
AWAKE_RUBBLE = re.compile(r'^mean awake floes [0-9.]+ \(of them, blocks of rubble ([0-9.]+)\)', re.MULTILINE)


def progress(text):
    """The progress lines as (simulated s, wall s since the start, awake floes, contacts), in order."""
    return [(float(m.group(1)), float(m.group(3)), int(m.group(4)), int(m.group(5))) for m in PROGRESS.finditer(text)]


def total(text):
    """(steps, wall s, ms per step, simulated s per wall s) of the closing line, or None if it is absent."""
    m = TOTAL.search(text)
    return (int(m.group(1)), float(m.group(2)), float(m.group(3)), float(m.group(4))) if m else None


def peak_memory_mb(text):
    """The process's peak resident memory (MB) it reports at its end, or None if it is absent."""
    m = PEAK.search(text)
    return float(m.group(1)) if m else None


def mean_awake_floes(text):
    """The mean awake floes per step over the whole run, from its closing lines, or None if they are absent (the
    summary's mean_awake_floes is over the steady part only)."""
    m = AWAKE.search(text)
    return float(m.group(1)) if m else None


def mean_awake_rubble(text):
    """Of the mean awake floes, the blocks of ridges' rubble; 0 when the run reports none."""
    m = AWAKE_RUBBLE.search(text)
    return float(m.group(1)) if m else 0.0
