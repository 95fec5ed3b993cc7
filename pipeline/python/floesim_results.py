#!/usr/bin/env python3
"""Read floesim's simulation results (results.h5, layouts floesim-results/1 to /12) with h5py and numpy only.

Results(path): the series with their columns and units, every body's state at a frame (frame(k) replays the frames
exactly as FrameReplay in pipeline/results_io.cpp), the floe outlines, a CSV of the series. Guide: README.md beside
this file; the layout: pipeline/results-layout.md. Command line: floesim_results.py FILE info | frame K | csv OUT.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import operator
import os
import sys
import tempfile
from dataclasses import dataclass

try:
    import h5py
    import numpy as np
except ImportError as e:  # run as a script by an interpreter without them: one line, not a traceback
    if __name__ != "__main__":
        raise
    print(f"floesim_results: {sys.executable}: no module {e.name}; install python3-h5py and python3-numpy "
          "(Debian's, for /usr/bin/python3) or pip install h5py numpy", file=sys.stderr)
    sys.exit(2)

LAYOUTS = [f"floesim-results/{v}" for v in range(1, 13)]  # /11 only adds dataset attributes to /10; /12 a series
_FIX_NOT_RESULTS = "give the results.h5 that floesim-simulate wrote"


class ResultsError(ValueError):
    """A file that cannot be read as asked; the message is 'FILE: what is wrong; the fix'."""


def _text(value) -> str:
    """An HDF5 string as h5py gives it (str, bytes, numpy.bytes_, a 0-d array) as str, NUL padding dropped."""
    if isinstance(value, np.ndarray):
        value = value.item() if value.size == 1 else value.ravel()[0]
    if isinstance(value, (bytes, np.bytes_)):
        value = bytes(value).decode("utf-8", "replace")
    return str(value).rstrip("\0")


def _texts(value) -> list[str]:
    """An array of strings (bytes or str elements), or one string, as a list of str."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return [_text(v) for v in value.ravel()]
    return [_text(value)]


@dataclass
class Frame:
    """Every body's state at one frame, the vessel first, then the floes in /geometry/floe_id order."""
    index: int
    time_s: float
    body_id: np.ndarray          # [n] int32: 0 = vessel, else the floe id
    geometry_index: np.ndarray   # [n] int: -1 for the vessel, else the index into the /geometry arrays
    position_m: np.ndarray       # [n x 3] centre of mass, world frame
    quaternion_wxyz: np.ndarray  # [n x 4] body to world
    in_contact: np.ndarray       # [n] int8: 1 = pressed against the vessel (all 0 before layout /4)


class Results:
    def __init__(self, path):
        self.path = os.fspath(path)
        if not os.path.exists(self.path):
            raise ResultsError(f"{self.path}: no such file; check the path, or run floesim-simulate first")
        if not h5py.is_hdf5(self.path):
            raise ResultsError(f"{self.path}: not an HDF5 file (or truncated); {_FIX_NOT_RESULTS}")
        try:
            self._file = h5py.File(self.path, "r")
        except OSError as e:
            raise ResultsError(f"{self.path}: cannot open ({e}); {_FIX_NOT_RESULTS}") from None
        try:
            self.attributes = self._read_attributes()
        except BaseException:
            self._file.close()
            raise
        self.layout = self.attributes["layout"]
        self.version = int(self.layout.rsplit("/", 1)[1])
        self._replay = None  # the replay state, made by the first frame()
        self._vertex_offset = None

    def _read_attributes(self) -> dict:
        if "floesim" not in self._file.attrs:
            raise ResultsError(f"{self.path}: no 'floesim' attribute: not a floesim results file; {_FIX_NOT_RESULTS}")
        try:
            attrs = json.loads(_text(self._file.attrs["floesim"]))
        except (ValueError, TypeError, OSError):
            attrs = None
        if not isinstance(attrs, dict):
            raise ResultsError(f"{self.path}: the 'floesim' attribute is not a JSON object; {_FIX_NOT_RESULTS}")
        if attrs.get("layout") not in LAYOUTS:
            raise ResultsError(f"{self.path}: layout {attrs.get('layout')!r} is not supported (this reader takes "
                               f"{LAYOUTS[0]} to {LAYOUTS[-1]}); read it with a newer floesim_results.py")
        return attrs

    def close(self):
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # --- datasets and their attributes ------------------------------------------------------------------------

    def _dataset(self, path: str) -> h5py.Dataset:
        """A dataset by its path; a bare name is a series ("ice_load" is /series/ice_load)."""
        full = path if "/" in path else "/series/" + path
        obj = self._file.get(full)
        if not isinstance(obj, h5py.Dataset):
            if full.startswith("/series/"):
                raise ResultsError(f"{self.path}: no series {full[8:]!r}; give one of "
                                   f"{', '.join(self.series_names())}")
            raise ResultsError(f"{self.path}: dataset {full} is missing (damaged, or not a floesim results file?); "
                               f"{_FIX_NOT_RESULTS}")
        return obj

    def _read(self, path: str, dtype) -> np.ndarray:
        return np.asarray(self._dataset(path)[()], dtype=dtype)

    @staticmethod
    def _cols(ds: h5py.Dataset) -> int:
        return 1 if ds.ndim < 2 else int(ds.shape[1])

    def _column_names(self, ds: h5py.Dataset) -> tuple[list[str], bool]:
        """The dataset's column names, and whether they came from its attribute (else the fallback)."""
        cols = self._cols(ds)
        if "columns" in ds.attrs:
            names = _texts(ds.attrs["columns"])
            if len(names) == cols:
                return names, True
        name = ds.name.rsplit("/", 1)[-1]
        return ([name] if cols == 1 else [f"{name}[{k}]" for k in range(cols)]), False

    def unit(self, path: str) -> str:
        ds = self._dataset(path)
        return _text(ds.attrs["unit"]) if "unit" in ds.attrs else ""

    def columns(self, path: str) -> list[str]:
        return self._column_names(self._dataset(path))[0]

    def column_units(self, path: str) -> list[str]:
        """Each column's unit: the attribute, else spread from unit() as the C++ does ("N, N m" over 6: 3 + 3)."""
        ds = self._dataset(path)
        cols = self._cols(ds)
        if "column_units" in ds.attrs:
            units = _texts(ds.attrs["column_units"])
            if len(units) == cols:
                return units
        units = self.unit(path).split(", ")
        if len(units) == cols:
            return units
        if len(units) == 2 and cols % 2 == 0:
            return [units[0]] * (cols // 2) + [units[1]] * (cols // 2)
        return [units[0]] * cols

    def doc(self, path: str) -> str:
        ds = self._dataset(path)
        return _text(ds.attrs["doc"]) if "doc" in ds.attrs else ""

    # --- series -----------------------------------------------------------------------------------------------

    def series_names(self) -> list[str]:
        group = self._file.get("/series")
        return [k for k, v in group.items() if isinstance(v, h5py.Dataset)] if isinstance(group, h5py.Group) else []

    def series(self, name: str) -> np.ndarray:
        """A per-step series as float64 [steps x cols] (cols 1 for a 1-D dataset)."""
        values = self._read("/series/" + name, np.float64)
        return values.reshape(len(values), -1)

    def steps(self) -> int:
        return len(self._dataset("/series/time_s"))

    # --- frames -----------------------------------------------------------------------------------------------

    def frame_times(self) -> np.ndarray:
        return self._read("/frames/time_s", np.float64)

    def frame_count(self) -> int:
        return len(self._dataset("/frames/time_s"))

    def _make_replay(self) -> dict:
        """Read /states and check it as FrameReplay's constructor does; the state that frame() walks forwards."""
        def fail(what):
            return ResultsError(f"{self.path}: {what}; {_FIX_NOT_RESULTS} (damaged file?)")

        ids = self._read("/geometry/floe_id", np.int32)
        n = len(ids)
        # Layout /1 had no fracture: nothing ends.
        ended = self._read("/geometry/floe_ended_s", np.float64) if self.version >= 2 else np.full(n, np.inf)
        if len(ended) != n:
            raise fail("/geometry/floe_ended_s and /geometry/floe_id have different lengths")
        # Slot 0 is the vessel, slot 1 + g the floe of geometry index g; lookup by id through the sorted ids.
        slot_ids = np.concatenate(([0], ids)).astype(np.int32)
        order = np.argsort(slot_ids, kind="stable")
        sorted_ids = slot_ids[order]
        twice = np.flatnonzero(sorted_ids[1:] == sorted_ids[:-1])
        if len(twice):
            bad = int(sorted_ids[twice[0]])
            vessel = " (the vessel's)" if bad == 0 else ""
            raise fail(f"body id {bad}{vessel} appears twice in /geometry/floe_id")
        times = self.frame_times()
        offset = self._read("/frames/offset", np.int64)
        body = self._read("/states/body_id", np.int32)
        rows = len(body)
        if len(offset) != len(times) + 1 or offset[0] != 0 or offset[-1] != rows:
            raise fail("/frames/offset does not match /states")
        down = np.flatnonzero(np.diff(offset) < 0)
        if len(down):
            raise fail(f"/frames/offset decreases at frame {down[0]}")
        position = self._read("/states/position_m", np.float64).reshape(-1, 3)
        quaternion = self._read("/states/quaternion_wxyz", np.float64).reshape(-1, 4)
        # Contact was not recorded before layout /4: no floe is shown in contact.
        contact = self._read("/states/in_contact", np.int8) if self.version >= 4 else np.zeros(rows, np.int8)
        if not len(position) == len(quaternion) == len(contact) == rows:
            raise fail("/states arrays have different lengths")
        # Every row's slot; the first frame with an unknown id or without the vessel fails (an unknown id first,
        # as the C++ checks each frame's rows before its vessel).
        at = np.minimum(np.searchsorted(sorted_ids, body), len(sorted_ids) - 1)
        unknown = np.flatnonzero(sorted_ids[at] != body)

        def frame_of(row):  # the frame holding a row: the last k with offset[k] <= row (empty frames skipped)
            return np.searchsorted(offset, row, side="right") - 1

        has_vessel = np.zeros(len(times), bool)
        has_vessel[frame_of(np.flatnonzero(body == 0))] = True
        no_vessel = np.flatnonzero(~has_vessel)
        bad_id_frame = int(frame_of(unknown[0])) if len(unknown) else len(times)
        if len(no_vessel) and no_vessel[0] < bad_id_frame:
            k = int(no_vessel[0])
            raise fail(f"frame {k} (t = {float(times[k])!r} s) has no vessel state (body_id 0)")
        if len(unknown):
            raise fail(f"frame {bad_id_frame} has a state for body {int(body[unknown[0]])}, which has no floe "
                       "geometry in /geometry/floe_id")
        return dict(times=times, offset=offset, position=position, quaternion=quaternion, contact=contact,
                    row_slot=order[at], slot_ids=slot_ids, ended=np.concatenate(([np.inf], ended)),
                    slot_row=np.full(n + 1, -1, np.int64), frame=-1)

    def frame(self, k: int) -> Frame:
        """Every body's state at frame k (FrameReplay::seek). Forwards costs the rows since the last frame asked
        for plus the bodies; backwards replays from frame 0."""
        k = operator.index(k)
        if self._replay is None:
            self._replay = self._make_replay()
        s = self._replay
        count = len(s["times"])
        if not 0 <= k < count:
            fix = f"give one of 0 .. {count - 1}" if count else "it has none: rerun with frames"
            raise ResultsError(f"{self.path}: frame {k} is out of range (the file has {count} frames); {fix}")
        slot_row = s["slot_row"]
        if k < s["frame"]:
            slot_row.fill(-1)
            s["frame"] = -1
        lo, hi = s["offset"][s["frame"] + 1], s["offset"][k + 1]
        if hi > lo:
            # Each body's last row among frames frame+1 .. k wins (the C++ loop assigns in row order): np.unique on
            # the reversed slots gives each slot's last occurrence.
            slots, last = np.unique(s["row_slot"][lo:hi][::-1], return_index=True)
            slot_row[slots] = hi - 1 - last
        s["frame"] = k
        # A floe that broke up is gone from the frame at its end time on (replaced by its pieces).
        t = s["times"][k]
        slot_row[s["ended"] <= t] = -1
        alive = np.flatnonzero(slot_row >= 0)
        rows = slot_row[alive]
        return Frame(index=k, time_s=float(t), body_id=s["slot_ids"][alive], geometry_index=alive - 1,
                     position_m=s["position"][rows], quaternion_wxyz=s["quaternion"][rows],
                     in_contact=s["contact"][rows])

    # --- geometry ---------------------------------------------------------------------------------------------

    def floe_outline(self, geometry_index: int) -> np.ndarray:
        """The CCW outline [V x 2] of floe `geometry_index` in its body frame (origin its centre of mass)."""
        if self._vertex_offset is None:
            self._vertex_offset = self._read("/geometry/floe_vertex_offset", np.int64)
        offset = self._vertex_offset
        if not 0 <= geometry_index < len(offset) - 1:
            raise ResultsError(f"{self.path}: no floe of geometry index {geometry_index}; the file has "
                               f"{len(offset) - 1} floes (0 .. {len(offset) - 2})")
        ds = self._dataset("/geometry/floe_vertices_m")
        return np.asarray(ds[offset[geometry_index]:offset[geometry_index + 1]], np.float64).reshape(-1, 2)

    def floe_outline_world(self, frame: Frame, i: int) -> np.ndarray:
        """Body i's outline [V x 3] in the world at the frame, on the slab's mid plane (body z = 0)."""
        g = int(frame.geometry_index[i])
        if g < 0:
            raise ResultsError(f"{self.path}: body {i} of frame {frame.index} is the vessel, which has no outline; "
                               "its mesh is /geometry/hull_vertices_m")
        outline = self.floe_outline(g)
        v = np.column_stack([outline, np.zeros(len(outline))])
        w, x, y, z = frame.quaternion_wxyz[i] / np.linalg.norm(frame.quaternion_wxyz[i])
        rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        return v @ rot.T + frame.position_m[i]

    # --- CSV --------------------------------------------------------------------------------------------------

    def to_csv(self, path, names=None, chunk_rows: int = 20000):
        """The per-step series (all, or `names`; time_s first) in one CSV, header `name.column [unit]`, values as
        Python's repr (shortest round trip). Written to a temporary file beside `path`, then renamed."""
        wanted = self.series_names() if names is None else list(names)
        order = ["time_s"] + [n for n in dict.fromkeys(wanted) if n != "time_s"]
        sets = [self._dataset("/series/" + n) for n in order]
        steps = len(sets[0])
        header = []
        for name, ds in zip(order, sets):
            if len(ds) != steps:
                raise ResultsError(f"{self.path}: series {name} has {len(ds)} rows, time_s {steps}; "
                                   f"{_FIX_NOT_RESULTS} (damaged file?)")
            cols, named = self._column_names(ds)
            units = [u or "-" for u in self.column_units(ds.name)]
            if len(cols) == 1:
                header.append(f"{name} [{units[0]}]")
            else:  # the fallback names are name[k] already
                header += [f"{name}.{c} [{u}]" if named else f"{c} [{u}]" for c, u in zip(cols, units)]
        out = os.fspath(path)
        folder = os.path.dirname(os.path.abspath(out))
        try:
            fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(out) + ".", suffix=".tmp", dir=folder)
        except OSError as e:
            raise ResultsError(f"{out}: cannot write ({e.strerror}); check that its folder exists and is writable") \
                from None
        try:
            with os.fdopen(fd, "w", newline="") as f:
                line = io.StringIO()
                csv.writer(line, lineterminator="\n").writerow(header)  # quotes a cell only if it needs it
                f.write(line.getvalue())
                for start in range(0, steps, chunk_rows):
                    stop = min(steps, start + chunk_rows)
                    block = np.hstack([np.asarray(ds[start:stop], np.float64).reshape(stop - start, -1)
                                       for ds in sets])
                    f.writelines(",".join(map(repr, row)) + "\n" for row in block.tolist())
                f.flush()
                os.fsync(f.fileno())
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes it 0600; a CSV is as readable as any new file
            os.replace(tmp, out)
        except BaseException as e:
            os.unlink(tmp)
            if isinstance(e, OSError):
                raise ResultsError(f"{out}: writing failed ({e.strerror or e}); check the disk and the folder, "
                                   f"and that {self.path} is complete") from None
            raise


def _info(r: Results) -> str:
    a = r.attributes
    lines = [f"{r.path}: layout {r.layout}, {r.steps()} steps, {r.frame_count()} frames",
             f"  time_step_s {a.get('time_step_s')}, duration_s {a.get('duration_s')}, "
             f"output_interval_s {a.get('output_interval_s')}", "series (columns [unit]):"]
    for name in r.series_names():
        cols, units = r.columns(name), r.column_units(name)
        lines.append(f"  {name}: " + ", ".join(f"{c} [{u or '-'}]" for c, u in zip(cols, units)))
    structures = r._file.get("/structures")
    if isinstance(structures, h5py.Group) and len(structures):
        lines.append("structures: " + ", ".join(structures.keys()))
    return "\n".join(lines)


def _frame_json(r: Results, k: int) -> str:
    f = r.frame(k)
    bodies = [{"id": int(f.body_id[i]), "position_m": f.position_m[i].tolist(),
               "quaternion_wxyz": f.quaternion_wxyz[i].tolist(), "in_contact": int(f.in_contact[i])}
              for i in range(len(f.body_id))]
    return json.dumps({"time_s": f.time_s, "bodies": bodies})


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="floesim_results", description="Read a floesim results.h5.")
    p.add_argument("file", metavar="FILE", help="results.h5 written by floesim-simulate")
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("info", help="layout, steps, frames, series with columns and units")
    fr = sub.add_parser("frame", help="every body's state at frame K as JSON (replay order)")
    fr.add_argument("k", metavar="K", type=int)
    cs = sub.add_parser("csv", help="the per-step series as one CSV")
    cs.add_argument("out", metavar="OUT")
    cs.add_argument("--series", nargs="+", metavar="NAME", help="only these series (time_s is always first)")
    args = p.parse_args(argv)
    text = None
    try:
        with Results(args.file) as r:
            if args.command == "info":
                text = _info(r)
            elif args.command == "frame":
                text = _frame_json(r, args.k)
            else:
                r.to_csv(args.out, args.series)
    except ResultsError as e:
        print(f"floesim_results: {e}", file=sys.stderr)
        return 2
    except (OSError, KeyError) as e:  # h5py on a damaged file
        print(f"floesim_results: {args.file}: cannot read ({e}); {_FIX_NOT_RESULTS} (damaged file?)", file=sys.stderr)
        return 2
    if text is not None:
        try:
            print(text)
            sys.stdout.flush()
        except BrokenPipeError:  # `| head`: the reader has what it wanted
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
