"""Packaging: the shipped files live once, in pounding/data/, and a wheel carries them.

* the checkout's top-level ``models/``, ``ground_motions/``, ``sweeps/`` and
  ``examples/`` are links to ``pounding/data/<name>`` (no second copy that could drift);
* the record catalogue is read from the package (``POUNDING_CATALOGUE`` still overrides);
* ``pounding init DIR`` copies the shipped models, sweeps and examples, and they work there;
* a wheel built from the sources holds every shipped file as a real file
  (``.ci/wheel_check.sh`` also installs it into a fresh venv and runs it from an empty folder).
"""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import tempfile
import tomllib
import zipfile
from pathlib import Path

import pytest

import pounding
from pounding.cli import main
from pounding.cli.init import init_folder
from pounding.data import STARTER_FOLDERS, catalogue_file, data_path
from pounding.records import catalogue as cat
from pounding.records.fema import fema_cache_dir

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "pounding" / "data"
LINKED = ("models", "ground_motions", "sweeps", "examples")


def _shipped(folder: Path) -> list[Path]:
    return sorted(p.relative_to(folder) for p in folder.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


@pytest.mark.parametrize("name", LINKED)
def test_top_level_folder_is_a_link_to_the_shipped_one(name):
    # A real folder here would be a second copy of the shipped files, free to drift.
    top = ROOT / name
    assert top.is_symlink(), f"{name}/ must be a symlink to pounding/data/{name} (one copy of the files)"
    assert top.resolve() == (DATA / name).resolve()
    assert (DATA / name).is_dir() and not (DATA / name).is_symlink()
    if (ROOT / ".git").exists() and shutil.which("git"):
        # Git records it as a symlink (mode 120000), not as files that happen to be linked here.
        listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-s", "--", name],
                                capture_output=True, text=True, check=True).stdout.split()
        assert listed[:1] == ["120000"], listed


def test_shipped_files_are_found_through_the_package():
    assert data_path("models", "pair.yaml").read_bytes() == (ROOT / "models" / "pair.yaml").read_bytes()
    assert catalogue_file() == data_path("ground_motions", "catalogue.yaml")
    assert catalogue_file().is_file()


def test_catalogue_comes_from_the_package_unless_overridden(tmp_path, monkeypatch):
    monkeypatch.delenv("POUNDING_CATALOGUE", raising=False)
    assert cat.catalogue_path() == catalogue_file()
    assert cat.load_entry("peer-northridge-1994-arleta-arl360").acceleration.size == 2000
    # A catalogue elsewhere reads its file sources relative to its own folder.
    copy = tmp_path / "my_motions"
    shutil.copytree(DATA / "ground_motions", copy)
    monkeypatch.setenv("POUNDING_CATALOGUE", str(copy / "catalogue.yaml"))
    assert cat.catalogue_path() == copy / "catalogue.yaml"
    assert cat.get_entry("synthetic-ricker-2hz").path == copy / "synthetic" / "ricker-2hz.txt"
    monkeypatch.setenv("POUNDING_CATALOGUE", str(tmp_path / "absent.yaml"))
    with pytest.raises(pounding.PoundingError, match="absent.yaml: the record catalogue is missing; point "
                                                     "POUNDING_CATALOGUE at an existing catalogue.yaml"):
        cat.load_catalogue()


def test_cache_folder_is_the_platform_user_cache(tmp_path, monkeypatch):
    monkeypatch.delenv("POUNDING_CACHE_DIR", raising=False)
    monkeypatch.delenv("POUNDING_NO_CACHE", raising=False)
    if sys.platform.startswith("linux"):
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
        assert fema_cache_dir() == tmp_path / "pounding"
    monkeypatch.setenv("POUNDING_CACHE_DIR", str(tmp_path / "mine"))
    assert fema_cache_dir() == tmp_path / "mine"


def test_init_copies_the_shipped_models_sweeps_and_examples(tmp_path, capsys, monkeypatch):
    target = tmp_path / "study"
    assert main(["init", str(target)]) == 0
    out = capsys.readouterr().out.splitlines()
    expected = [Path(name) / rel for name in STARTER_FOLDERS for rel in _shipped(DATA / name)]
    assert sorted(p.relative_to(target) for p in target.rglob("*") if p.is_file()) == sorted(expected)
    assert out[:-1] == [f"wrote {target / rel}" for rel in expected]
    assert out[-1] == f"{len(expected)} files; next: cd {target} && pounding run models/pair.yaml -o pair.nc"
    for rel in expected:
        assert (target / rel).read_bytes() == (DATA / rel).read_bytes(), rel
        assert (target / rel).stat().st_mode & stat.S_IWUSR  # the user's to edit
    # Every model's record, and every sweep's model, resolves inside the new folder.
    from pounding.model.model import load_model
    from pounding.simulation import component_records, record_for
    from pounding.studies.sweep.spec import load_sweep

    monkeypatch.chdir(target)
    for model_file in sorted(Path("models").glob("*.yaml")):
        model = load_model(model_file)
        if model.ground_motion.two_components:   # a model in plan: its record pair
            records = component_records(model)
            assert all(r is None or r.acceleration.size > 1000 for r in records), model_file
            continue
        assert record_for(model).acceleration.size > 1000, model_file
    for sweep_file in sorted(Path("sweeps").glob("*.yaml")):
        assert load_sweep(sweep_file) is not None, sweep_file


def test_init_into_an_empty_folder(tmp_path):
    written = init_folder(tmp_path)
    assert (tmp_path / "models" / "pair.yaml") in written


def test_init_refuses_to_overwrite(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("mine")
    assert main(["init", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err == (f"pounding: error: {tmp_path}: the folder is not empty; give a new or empty folder "
                   f"(e.g. pounding init {tmp_path.name}-new) so that no file is overwritten\n")
    assert main(["init", str(tmp_path / "notes.txt")]) == 2
    assert capsys.readouterr().err == (f"pounding: error: {tmp_path / 'notes.txt'}: is a file; give a new folder, "
                                       "e.g. pounding init pounding-study\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def test_version_is_written_once(capsys):
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "pounding.__version__"}
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out == f"pounding {pounding.__version__}\n"


def test_wheel_holds_every_shipped_file(tmp_path):
    # Build from a copy of what the wheel is made of (no build/ or egg-info in the checkout).
    pytest.importorskip("build", reason="the wheel test needs `pip install build` (in the test extra)")
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    shutil.copytree(ROOT / "pounding", source / "pounding", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    result = subprocess.run([sys.executable, "-m", "build", "--wheel", "--outdir", str(tmp_path / "dist"),
                             str(source)], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    (wheel,) = (tmp_path / "dist").glob("pounding-*.whl")
    assert wheel.name.startswith(f"pounding-{pounding.__version__}-py3-none-any")
    with zipfile.ZipFile(wheel) as archive:
        infos = {info.filename: info for info in archive.infolist()}
        metadata = archive.read(f"pounding-{pounding.__version__}.dist-info/METADATA").decode()
        entry_points = archive.read(f"pounding-{pounding.__version__}.dist-info/entry_points.txt").decode()
    for rel in _shipped(DATA):
        info = infos.get(f"pounding/data/{rel.as_posix()}")
        assert info is not None, f"{rel} is not in the wheel"
        assert stat.S_ISLNK(info.external_attr >> 16) is False, f"{rel} is a link in the wheel"
        assert info.file_size == (DATA / rel).stat().st_size, rel
    # Every module of the package, not only the top level.
    modules = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "pounding").rglob("*.py")
                     if "__pycache__" not in p.parts)
    assert [m for m in modules if m not in infos] == []
    assert f"Version: {pounding.__version__}" in metadata
    assert "Requires-Dist: numba<0.69,>=0.67" in metadata and "Requires-Dist: platformdirs" in metadata
    assert "pounding = pounding.cli:console_main" in entry_points


def test_read_only_install_caches_compiled_code_in_the_user_cache(tmp_path, monkeypatch):
    # A __pycache__ that is a file cannot be written, even by root: a stand-in for a read-only site-packages.
    from numba.core import config

    from pounding.numba_cache import use_writable_cache

    monkeypatch.setattr(config, "CACHE_DIR", "")
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    package = tmp_path / "site-packages" / "pounding" / "contact"
    package.mkdir(parents=True)
    (package / "laws.py").write_text("")
    assert use_writable_cache(package / "laws.py") is None and config.CACHE_DIR == ""  # writable: numba's own place
    shutil.rmtree(package / "__pycache__")
    (package / "__pycache__").write_text("read-only stand-in")
    if sys.platform.startswith("linux"):
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
        assert use_writable_cache(package / "laws.py") == str(tmp_path / "cache" / "pounding" / "numba")
        assert config.CACHE_DIR == str(tmp_path / "cache" / "pounding" / "numba")
        # No writable user cache either: a folder in the temporary directory, never numba's RuntimeError.
        monkeypatch.setattr(config, "CACHE_DIR", "")
        (tmp_path / "file").write_text("")
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "file"))
        monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
        assert use_writable_cache(package / "laws.py") == str(tmp_path / "tmp" / f"pounding-numba-{os.getuid()}")
    # NUMBA_CACHE_DIR (numba's config) set by the user always wins.
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path / "mine"))
    assert use_writable_cache(package / "laws.py") is None and config.CACHE_DIR == str(tmp_path / "mine")
