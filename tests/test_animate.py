"""``pounding animate``: the film of a run archive.

What is checked: the drawn floors (elevation) and floor outlines (plan) touch exactly when the recorded gap
closes (the gaps are drawn exaggerated as the displacements are); the frame count and frame rate follow the
window and the speed; an impact's frame shows its flash at the contact and its neighbours do not; the GIF
and the MP4 hold the frames at the rate announced; bad inputs are refused in one line and a failed write
keeps the old file.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main
from pounding.results.animation import FRAME_RATE, RunAnimation, frame_indices

from plan_cases import CORNER

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")


@pytest.fixture(scope="module")
def pair_run(tmp_path_factory):
    """models/pair.yaml for 4 s (impacts from 3.45 s on, 0.01 s samples): its archive's path."""
    path = tmp_path_factory.mktemp("animate") / "pair.nc"
    assert main(["run", PAIR, "--duration", "4", "-o", str(path)]) == 0
    return path


@pytest.fixture(scope="module")
def pair(pair_run):
    from pounding.cli.run import open_archive

    return open_archive(pair_run)[1]


#: The plan case under wave passage: B's ground lags A's by 0.2 s (a 10 m offset at 50 m/s), so the two
#: grounds differ by up to 7 cm, more than the 2 cm joint (each floor is archived relative to its own ground).
WAVE = "wave_passage: {apparent_velocity: 50.0, position: {A: 0.0, B: 10.0}}"


@pytest.fixture(scope="module", params=["one ground", "wave passage"])
def corner(request):
    """The plan case of tests/plan_cases.py (A eccentric, B at its corner, a wall) for 4.2 s: impacts of A and
    B from 3.68 s on; and the same under wave passage."""
    import pounding
    from pounding.model.model import model_from_text

    text = CORNER if request.param == "one ground" else CORNER.replace("angle: 30,", f"angle: 30, {WAVE},")
    assert request.param == "one ground" or WAVE in text
    return pounding.simulate(model_from_text(text, name="corner"), duration=4.2)


def _line(film, gid):
    return next(line for line in film.ax.get_lines() if line.get_gid() == gid)


def test_the_drawn_floors_touch_when_the_gap_closes_in_elevation(pair):
    """Between the right end of A's slab and the left end of B's at each contact's floor the drawing leaves
    X·(gap − (u_A − u_B)) = −X·penetration: zero exactly when the archive's gap closes."""
    film = RunAnimation(pair, window=(3.0, 4.0))
    factor = film.exaggerate
    for k in range(film.n_frames):
        film.draw(k)
        i = int(film.indices[k])
        a_x, a_z = _line(film, "building A").get_data()
        b_x, b_z = _line(film, "building B").get_data()
        for c, level in enumerate(pair.level_left.values):
            z = float(pair.elevation.sel(floor=f"A:{level}"))
            right_of_a = np.nanmax(np.where(np.isclose(a_z, z), a_x, np.nan))
            left_of_b = np.nanmin(np.where(np.isclose(b_z, z), b_x, np.nan))
            # round-off of the drawn coordinates (tens of m) only
            assert left_of_b - right_of_a == pytest.approx(-factor * float(pair.penetration.values[i, c]), abs=1e-9)


def test_the_drawn_outlines_touch_when_the_gap_closes_in_plan(corner):
    """A contact point drawn on A's face and the same point of B's face (read off B's drawn outline, between
    the two corners of that face) lie X·(−penetration) apart along the face's normal."""
    joints = [c for c in range(corner.sizes["contact"]) if str(corner.building_right.values[c]) == "B"]
    first = float(corner.impact_time.values[np.isin(corner.impact_contact.values, joints)].min())
    film = RunAnimation(corner, window=(first - 0.2, min(first + 0.5, float(corner.time.values[-1]))))
    factor = film.exaggerate
    assert joints and film.forces[:, joints].max() > 0   # B strikes A in the window
    for k in range(film.n_frames):
        film.draw(k)
        i = int(film.indices[k])
        points = np.column_stack(_line(film, "contacts").get_data())
        outline = np.column_stack(_line(film, "floor B:1").get_data())[:4]
        rest = np.column_stack([corner.corner_x.sel(floor="B:1").values, corner.corner_y.sel(floor="B:1").values])
        for c in joints:
            assert str(corner.point_normal.values[c]) == "x"
            face = np.flatnonzero(np.isclose(rest[:, 0], rest[:, 0].min()))       # B's west face: two corners
            y0, y1 = rest[face, 1]
            fraction = (float(corner.point_y.values[c]) - y0) / (y1 - y0)
            on_b = (1.0 - fraction) * outline[face[0]] + fraction * outline[face[1]]
            # the outline and the point move with the same small-rotation kinematics: round-off
            assert on_b[0] - points[c, 0] == pytest.approx(-factor * float(corner.penetration.values[i, c]), abs=1e-9)


@pytest.mark.parametrize("speed, window", [(1.0, None), (0.1, (3.2, 3.5)), (0.5, (0.0, 1.0)), (4.0, (1.0, 3.99))])
def test_the_frames_follow_the_window_and_the_speed(pair, speed, window):
    """Frames are stored samples S/fps simulated seconds apart (a whole number of samples), the rate as
    close to FRAME_RATE as that allows (every sample in slow motion), covering the window from its start."""
    indices, fps = frame_indices(pair, speed, window)
    t = pair.time.values
    start, end = window or (t[0], t[-1])
    step = speed / fps                                   # simulated seconds between frames
    samples = step / 0.01                                # the archive's samples are 0.01 s apart
    assert samples == pytest.approx(round(samples), abs=1e-9) and round(samples) >= 1
    if round(samples) > 1:                               # no other whole number of samples comes closer to the rate
        assert abs(fps - FRAME_RATE) <= min(abs(speed / ((round(samples) + d) * 0.01) - FRAME_RATE) for d in (-1, 1))
    else:
        assert fps <= FRAME_RATE * 1.5
    assert indices.size == int(np.floor((end - start) / step + 1e-9)) + 1
    np.testing.assert_allclose(np.diff(t[indices]), step, rtol=1e-9)
    assert t[indices[0]] == pytest.approx(start, abs=1e-9) and t[indices[-1]] <= end + 1e-9


def _quiet_frames(ds, film, contact):
    """Frames k whose interval holds an impact onset at *contact* while the intervals of k-1 and k+1 hold no force
    at it at all (no onset, no trace sample, no sampled force > 0), from the archive itself."""
    times = film.times
    low = np.r_[times[0] - (times[1] - times[0]), times[:-1]]

    def forces(k):
        def inside(at):
            return (at > low[k]) & (at <= times[k])
        mine = ds.trace_contact.values == contact
        return np.r_[ds.impact_peak_force.values[(ds.impact_contact.values == contact) & inside(ds.impact_time.values)],
                     ds.trace_force.values[mine & inside(ds.trace_time.values)],
                     ds.contact_force.values[inside(ds.time.values), contact]]

    onsets = [k for k in range(1, film.n_frames - 1)
              if np.any((ds.impact_contact.values == contact) & (ds.impact_time.values > low[k])
                        & (ds.impact_time.values <= times[k]))]
    return [(k, forces(k).max()) for k in onsets if forces(k - 1).max(initial=0) == 0 == forces(k + 1).max(initial=0)]


def test_an_impact_flashes_at_its_contact_in_its_frame_only(pair):
    from pounding.results.summary import force_text

    film = RunAnimation(pair, window=(3.0, 4.0))
    found = [(c, k, peak) for c in range(pair.sizes["contact"]) for k, peak in _quiet_frames(pair, film, c)]
    assert found, "no isolated impact in the window"
    c, k, peak = found[0]
    np.testing.assert_allclose(film.forces[k, c], peak, rtol=1e-12)    # the largest force of the interval
    assert film.forces[k - 1, c] == 0 == film.forces[k + 1, c]
    film.draw(k)
    colour = np.round(255 * np.array(film.flash.cmap(film.flash.norm(peak))[:3]))
    row, col = film.pixel(*film.flash.get_offsets()[c])
    label = next(t for t in film.ax.texts if t.get_visible() and t.get_text() == force_text(peak))
    assert label.get_position()[1] == pytest.approx(float(film.flash.get_offsets()[c][1]))

    def flash_pixels(frame):
        box = frame[row - 8:row + 9, col - 8:col + 9].astype(float)   # the marker: 40-300 pt², 7-20 px across
        return int((np.abs(box - colour).max(axis=-1) < 12).sum())    # 12 of 255: anti-aliasing at the edge

    before, during, after = (flash_pixels(film.frame(j)) for j in (k - 1, k, k + 1))
    assert during >= 20 and before == 0 and after == 0, (before, during, after)


def test_a_gif_holds_every_frame_at_the_announced_rate(pair_run, pair, tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "pair.gif"
    # A 0.3 s window (16 frames, ~0.25 s each to draw and quantise): every frame and the rate are checked
    # as on a longer one.
    assert main(["animate", str(pair_run), "-o", str(out), "--window", "3,3.3", "--speed", "0.5"]) == 0
    indices, fps = frame_indices(pair, 0.5, (3.0, 3.3))
    assert fps == pytest.approx(25.0) and indices.size == 16          # 0.02 s of the run a frame: 0.3 / 0.02 + 1
    with Image.open(out) as gif:
        assert gif.format == "GIF" and gif.n_frames == indices.size
        assert gif.info["duration"] == 40                               # ms: 1 / 25 s
    assert f"{indices.size} frames at 25 frames/s" in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir()] == ["pair.gif"]         # no temporary left


def test_an_mp4_holds_every_frame_at_the_announced_rate(pair_run, pair, tmp_path):
    """CI installs ffmpeg (.ci/run): missing, this fails rather than skips."""
    assert shutil.which("ffmpeg") and shutil.which("ffprobe"), "ffmpeg is not installed (Debian: apt-get install ffmpeg)"
    out = tmp_path / "pair.mp4"
    assert main(["animate", str(pair_run), "-o", str(out), "--window", "3,3.5"]) == 0
    indices, fps = frame_indices(pair, 1.0, (3.0, 3.5))
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=codec_name,nb_read_frames,r_frame_rate", "-of", "json", str(out)],
                           capture_output=True, text=True, check=True)
    stream = json.loads(probe.stdout)["streams"][0]
    assert stream["codec_name"] == "h264" and int(stream["nb_read_frames"]) == indices.size == 13
    num, den = (int(x) for x in stream["r_frame_rate"].split("/"))
    assert num / den == pytest.approx(fps) == pytest.approx(25.0)


def test_bad_inputs_are_refused_in_one_line(pair_run, tmp_path, capsys, monkeypatch):
    from matplotlib.animation import FFMpegWriter

    text = tmp_path / "notes.nc"
    text.write_text("not NetCDF\n")
    study = tmp_path / "pushover.nc"
    xr.Dataset(attrs={"source": "pounding 1", "kind": "pushover"}).to_netcdf(study)
    cases = {
        (str(pair_run), "-o", str(tmp_path / "a.webm")): "unknown suffix .webm; write .mp4",
        (str(pair_run), "-o", str(tmp_path / "a.gif"), "--window", "3,9"): "the run spans 0 to 4 s",
        (str(pair_run), "-o", str(tmp_path / "a.gif"), "--window", "3"): "give two times in s",
        (str(pair_run), "-o", str(tmp_path / "a.gif"), "--speed", "-1"): "--speed -1: give a positive",
        (str(pair_run), "-o", str(tmp_path / "a.gif"), "--exaggerate", "0"): "--exaggerate 0: give a positive",
        (str(text), "-o", str(tmp_path / "a.gif")): "not a readable NetCDF file",
        (str(study), "-o", str(tmp_path / "a.gif")): "a pushover archive; pounding animate draws the archive of one run",
    }
    for args, words in cases.items():
        assert main(["animate", *args]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err, (args, err)
    monkeypatch.setattr(FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    assert main(["animate", str(pair_run), "-o", str(tmp_path / "a.mp4")]) == 2
    err = capsys.readouterr().err
    assert "needs ffmpeg" in err and "write a .gif" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.nc", "pushover.nc"]   # nothing written


def test_a_film_that_fails_midway_keeps_the_old_file(pair_run, tmp_path, capsys, monkeypatch):
    out = tmp_path / "old.gif"
    out.write_bytes(b"the old film")
    real = RunAnimation.draw

    def draw(self, k):
        if k == 3:
            raise OSError(28, "No space left on device")
        real(self, k)

    monkeypatch.setattr(RunAnimation, "draw", draw)
    assert main(["animate", str(pair_run), "-o", str(out), "--window", "3,3.5", "--overwrite"]) == 2
    assert "No space left on device" in capsys.readouterr().err
    assert out.read_bytes() == b"the old film" and [p.name for p in tmp_path.iterdir()] == ["old.gif"]
    assert main(["animate", str(pair_run), "-o", str(out), "--window", "3,3.5"]) == 2   # no --overwrite
    assert "exists" in capsys.readouterr().err
