#!/usr/bin/python3
"""Measurements as data: the benchmark scripts append the figures they print to a CSV file through this module.

Every row is one figure:

  figure,value,unit,command,commit,machine,date

  figure   what was measured, a short name (e.g. "box2d_ratio", "seed 1 floesim speed")
  value    the figure as the script printed it (a number, or a short text such as a failure map cell "S>B")
  unit     its unit ("-" for a ratio or a count)
  command  the command line as it was run
  commit   `git rev-parse --short HEAD` of the repository, with "+dirty" when its tree has changes
  machine  CPU model (/proc/cpuinfo) and core count
  date     UTC date, ISO 8601

A file is rewritten whole under a temporary name in its folder and renamed over the old one, so a reader never sees
half a file and an interrupted script leaves the old rows as they were. Standard library only.

As a module (how the bench scripts use it, imported with sys.path from the script's own location):

  rec = measured.Recorder('sim/bench/measured/versus-box2d.csv')
  rec.add('box2d_ratio', f'{mean:.2f}', '-')
  rec.write()

As a wrapper for the C++ benchmarks, which print their figures but do not write CSV: runs the command, passes its
output through unchanged, then records the figures it recognises in that output (floesim-bench, digitise_bench,
render_bench; the bench is recognised by the executable's name):

  pipeline/bench/measured.py --record sim/bench/measured/floesim-bench.csv -- build/bin/floesim-bench --scales 1
"""
import csv
import datetime
import io
import os
import re
import shlex
import subprocess
import sys
import tempfile

HEADER = ['figure', 'value', 'unit', 'command', 'commit', 'machine', 'date']
REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..'))


def commit(repo=REPO):
    """`git rev-parse --short HEAD` of repo, '+dirty' appended when tracked files differ from HEAD."""
    try:
        head = subprocess.run(['git', '-C', repo, 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True,
                              check=True).stdout.strip()
        dirty = subprocess.run(['git', '-C', repo, 'status', '--porcelain', '--untracked-files=no'],
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'
    return head + ('+dirty' if dirty else '')


def machine():
    """A short description of this machine: CPU model and core count."""
    model = None
    try:
        with open('/proc/cpuinfo') as f:
            for line in f:
                if line.startswith('model name'):
                    model = line.split(':', 1)[1].strip()
                    break
    except OSError:
        pass
    n = os.cpu_count() or 0
    return f'{model or "unknown CPU"}, {n} core{"s" if n != 1 else ""}'


def utc_date():
    return datetime.datetime.now(datetime.timezone.utc).date().isoformat()


def command_line(argv=None):
    """The command line as it was run (the script as it was named, then its arguments)."""
    return shlex.join(sys.argv if argv is None else argv)


def read_rows(path):
    """The rows of a measurement CSV (dicts by HEADER), [] if it does not exist."""
    if not os.path.exists(path):
        return []
    with open(path, newline='') as f:
        r = csv.DictReader(f)
        if r.fieldnames != HEADER:
            sys.exit(f'{path}: not a measurement file (its header is {",".join(r.fieldnames or [])}, '
                     f'expected {",".join(HEADER)})')
        return list(r)


def write_rows(path, rows):
    """Writes rows (dicts by HEADER) to path atomically: a temporary file in the same folder, then a rename."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=HEADER, lineterminator='\n')
    w.writeheader()
    w.writerows(rows)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix='.' + os.path.basename(path) + '.', suffix='.tmp')
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)  # mkstemp makes the file private; a data file is as readable as any other
        with os.fdopen(fd, 'w', newline='') as f:
            f.write(buf.getvalue())
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


class Recorder:
    """Collects figures of one run and appends them to a measurement CSV in one atomic write.

    command, commit, machine and date are taken once, when the recorder is made (the command line defaults to
    sys.argv as run)."""

    def __init__(self, path, command=None, repo=REPO):
        self.path = path
        self.stamp = {'command': command if command is not None else command_line(), 'commit': commit(repo),
                      'machine': machine(), 'date': utc_date()}
        self.rows = []

    def add(self, figure, value, unit='-'):
        self.rows.append(dict(self.stamp, figure=figure, value=str(value), unit=unit))

    def write(self):
        if not self.rows:
            return 0
        write_rows(self.path, read_rows(self.path) + self.rows)
        print(f'recorded {len(self.rows)} figures in {self.path}', file=sys.stderr)
        n, self.rows = len(self.rows), []
        return n


def add_record_option(ap):
    """The --record CSV option every bench script takes."""
    ap.add_argument('--record', metavar='CSV',
                    help='append the figures printed to this measurement CSV (figure,value,unit,command,commit,'
                         'machine,date; e.g. the bench\'s measured/ folder)')


# The C++ benchmarks' output: what to record from each line (patterns on the text they print).

def parse_floesim_bench(text):
    figs, field = [], None
    for line in text.splitlines():
        m = re.match(r'field (\d+)x, (.*?): [0-9.]+ m x [0-9.]+ m, (\d+) floes \((\d+) convex parts\)', line)
        if m:
            field = f'{m.group(1)}x {m.group(2)}'
            figs += [(f'{field} floes', m.group(3), '-'), (f'{field} convex parts', m.group(4), '-')]
            continue
        m = re.match(r'\s+per step \(mean\): awake floes ([0-9.]+), contacts ([0-9.]+), broad-phase part pairs '
                     r'([0-9.]+), solver sweeps ([0-9.]+)', line)
        if m and field:
            figs += [(f'{field} awake floes per step', m.group(1), '-'), (f'{field} contacts per step', m.group(2), '-'),
                     (f'{field} broad-phase pairs per step', m.group(3), '-'),
                     (f'{field} solver sweeps per step', m.group(4), '-')]
            continue
        m = re.match(r'\s+steps \d+, wall [0-9.]+ s, ([0-9.]+) ms/step, ([0-9.]+) simulated s per wall s', line)
        if m and field:
            figs += [(f'{field} ms per step', m.group(1), 'ms'),
                     (f'{field} speed', m.group(2), 'simulated s per wall s')]
            continue
        m = re.match(r'\s+peak memory \(ru_maxrss, whole process so far\) ([0-9.]+) MB', line)
        if m and field:
            figs.append((f'{field} peak memory', m.group(1), 'MB'))
            continue
        m = re.match(r'\s+brash: ([0-9.]+) t removed; rigid contacts carry ([-0-9.]+) % of the mean surge ice load',
                     line)
        if m and field:
            figs += [(f'{field} brash removed', m.group(1), 't'),
                     (f'{field} rigid share of the mean surge ice load', m.group(2), '%')]
            continue
        m = re.match(r'speed ratio against (.*): ([0-9.eE+-]+)$', line.strip())
        if m:
            figs.append((f'speed ratio of the defaults against {m.group(1)}', m.group(2), '-'))
            continue
        m = re.match(r'(fracture_speed_ratio|rigid_brash_speed_ratio|realtime_factor) ([0-9.eE+-]+)$', line.strip())
        if m:
            figs.append((m.group(1), m.group(2), 'simulated s per wall s' if m.group(1) == 'realtime_factor'
                         else '-'))
    return figs


def parse_digitise_bench(text):
    figs = []
    for line in text.splitlines():
        # The means row: "mean", then precision, recall, F1, mean IoU, pixel IoU, concentration error, KS, seconds.
        f = line.split()
        if len(f) == 9 and f[0] == 'mean' and all(re.fullmatch(r'[-+]?[0-9.]+', x) for x in f[1:]):
            figs += [('mean precision', f[1], '-'), ('mean recall', f[2], '-'), ('mean F1 (IoU >= 0.5)', f[3], '-'),
                     ('mean IoU', f[4], '-'), ('mean pixel IoU', f[5], '-'), ('mean concentration error', f[6], '-'),
                     ('mean KS distance of log areas', f[7], '-'), ('mean time per image', f[8], 's')]
        m = re.search(r'mean \|conc\. error\| ([0-9.]+), max time ([0-9.]+) s, objective ([0-9.]+)', line)
        if m:
            figs += [('mean absolute concentration error', m.group(1), '-'), ('largest time per image', m.group(2), 's'),
                     ('objective', m.group(3), '-')]
        m = re.match(r'synthetic default image .*: F1 ([0-9.]+), mean IoU ([0-9.]+), conc\. error ([-+0-9.]+), '
                     r'KS ([0-9.]+), ([0-9.]+) s', line)
        if m:
            figs += [('synthetic default image F1', m.group(1), '-'), ('synthetic default image mean IoU', m.group(2), '-'),
                     ('synthetic default image concentration error', m.group(3), '-'),
                     ('synthetic default image KS distance', m.group(4), '-'),
                     ('synthetic default image time', m.group(5), 's')]
    return figs


def parse_render_bench(text):
    figs = []
    for line in text.splitlines():
        m = re.match(r'strip chart alone: ([0-9.]+) ms/frame', line)
        if m:
            figs.append(('strip chart alone', m.group(1), 'ms/frame'))
        m = re.match(r'(\w+)\s+\d+x\d+ ss\d+, \d+ floes, \d+ frames: ([0-9.]+) ms/frame render \+ ([0-9.]+) ms/frame '
                     r'encode \(([0-9.]+) ms/frame wall', line)
        if m:
            figs += [(f'{m.group(1)} render', m.group(2), 'ms/frame'), (f'{m.group(1)} encode', m.group(3), 'ms/frame'),
                     (f'{m.group(1)} wall', m.group(4), 'ms/frame')]
    return figs


PARSERS = {'floesim-bench': parse_floesim_bench, 'digitise_bench': parse_digitise_bench,
           'render_bench': parse_render_bench}


def main():
    args = sys.argv[1:]
    if '--' not in args or len(args) < 4 or args[0] != '--record':
        sys.exit('usage: pipeline/bench/measured.py --record CSV -- BENCH [ARGS...]\n'
                 f'  BENCH one of {", ".join(sorted(PARSERS))}: runs it, passes its output through and appends the '
                 'figures it printed to CSV')
    path, cmd = args[1], args[args.index('--') + 1:]
    parse = PARSERS.get(os.path.basename(cmd[0]))
    if parse is None:
        sys.exit(f'measured.py: no parser for {os.path.basename(cmd[0])} (known: {", ".join(sorted(PARSERS))})')
    rec = Recorder(path, command=shlex.join(cmd))  # the bench's own command line, as the README gives it
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)
    out = []
    for line in proc.stdout:
        sys.stdout.write(line)
        sys.stdout.flush()
        out.append(line)
    if proc.wait():
        sys.exit(f'measured.py: {cmd[0]} failed (exit {proc.returncode}); nothing recorded')
    for fig in parse(''.join(out)):
        rec.add(*fig)
    if not rec.rows:
        sys.exit(f'measured.py: no figures recognised in the output of {cmd[0]}')
    rec.write()


if __name__ == '__main__':
    main()
