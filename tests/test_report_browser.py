"""Every kind's ``pounding report`` opened in a real browser (Debian's headless Chromium): every image
loads, no script error occurs, and a screenshot of each is kept in ci-artifacts/report-screenshots/.

The report has no script of its own; the test adds a probe at the top of a copy of it that records,
once the page has loaded, each image's state (complete, with a natural width) and every error event,
and writes them into the page, which ``--dump-dom`` prints.  Chromium runs without network (every host
name resolves to nothing): the report must need none.  Without Chromium the test fails (CI installs it,
.ci/run), it does not skip.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from pounding.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report_archives import KINDS, build_archives  # noqa: E402

ARTIFACTS = Path(__file__).resolve().parents[1] / "ci-artifacts" / "report-screenshots"

PROBE = """<script>
window.__errors = [];
window.addEventListener("error", function (e) { window.__errors.push(String(e.message || e.type)); }, true);
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                     .map(function (i) { return i.alt; });
  var out = document.createElement("pre");
  out.id = "pounding-probe";
  out.textContent = JSON.stringify({images: images.length, broken: broken, errors: window.__errors});
  document.body.appendChild(out);
});
</script>"""


@pytest.fixture(scope="module")
def chromium() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        pytest.fail("Chromium is not installed: `apt-get install -y chromium` (Debian; .ci/run installs it); the "
                    "reports are tested in a real browser")
    return found


@pytest.fixture(scope="module")
def archives(tmp_path_factory, studies_in_process):
    return build_archives(tmp_path_factory.getbasetemp())


def _browse(chromium: str, page: Path, profile: Path, *extra: str) -> subprocess.CompletedProcess:
    """Chromium headless on the file *page*: no network, no GPU, a fresh profile."""
    argv = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--host-resolver-rules=MAP * ~NOTFOUND", f"--user-data-dir={profile}", *extra, page.as_uri()]
    return subprocess.run(argv, capture_output=True, text=True, timeout=120)


def probe(chromium: str, html: Path, tmp_path: Path) -> dict:
    """What the probe saw of *html* once loaded: ``{"images": n, "broken": [alt...], "errors": [...]}``."""
    probed = tmp_path / f"probed-{html.name}"
    text = html.read_text(encoding="utf-8")
    probed.write_text(text.replace("<head>", "<head>" + PROBE, 1), encoding="utf-8")
    done = _browse(chromium, probed, tmp_path / "profile", "--virtual-time-budget=10000", "--dump-dom")
    found = re.search(r'<pre id="pounding-probe">(.*?)</pre>', done.stdout, re.S)
    assert found, f"the probe did not report (Chromium exit {done.returncode}): {done.stderr[-500:]}"
    return json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def test_the_probe_sees_a_broken_image_and_a_script_error(chromium, tmp_path):
    """The check below can fail: a page with an undecodable image and a failing script is caught."""
    page = tmp_path / "bad.html"
    page.write_text('<!DOCTYPE html><html><head></head><body><img alt="bad" src="data:image/png;base64,AAAA">'
                    "<script>undefined_function();</script></body></html>", encoding="utf-8")
    seen = probe(chromium, page, tmp_path)
    assert seen["broken"] == ["bad"]
    assert any("undefined_function" in e for e in seen["errors"])


@pytest.mark.parametrize("name", list(KINDS))
def test_each_kind_opens_in_chromium_with_every_image_loaded(name, chromium, archives, tmp_path):
    report = tmp_path / f"{name}.html"
    assert main(["report", str(archives[name]), "-o", str(report)]) == 0
    embedded = report.read_text(encoding="utf-8").count("<img ")
    seen = probe(chromium, report, tmp_path)
    assert seen == {"images": embedded, "broken": [], "errors": []} and embedded > 0
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    shot = ARTIFACTS / f"{name}.png"
    shot.unlink(missing_ok=True)
    _browse(chromium, report, tmp_path / "profile", "--window-size=1280,3000", f"--screenshot={shot}")
    from matplotlib.image import imread

    pixels = imread(shot)
    assert pixels.shape[:2] == (3000, 1280) and pixels.std() > 0.05   # a page drawn, not a blank canvas
