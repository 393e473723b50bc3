"""The documentation site builds with warnings as errors, and says what it should.

The build (``sphinx-build -W --keep-going -b html docs OUT``) runs once per session in a
subprocess; it executes nothing but autodoc's imports (notebooks are rendered as stored).
Skipped when the ``docs`` extra (sphinx, numpydoc, myst-nb, furo) is not installed. The
checks of the project's metadata files (LICENSE, CITATION.cff, py.typed) and of the
names the pages refer to need no Sphinx.
"""

from __future__ import annotations

import html
import os
import importlib
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
#: the hand-written pages (the API pages are generated from the docstrings)
PAGES = sorted([*DOCS.glob("*.md"), *(DOCS / "guide").glob("*.md")])
ROLE = re.compile(r"\{(?:func|class|meth|mod|data|exc|attr)\}`~?(snapping[\w.]*)`")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    import importlib.util

    missing = [m for m in ("sphinx", "numpydoc", "myst_nb", "furo") if importlib.util.find_spec(m) is None]
    if missing:
        why = (f"the docs extra is not installed ({', '.join(missing)} missing): the docs build and its checks "
               f"are not run; install .[test,distributed,docs] (the README's test command)")
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail(f"CI: {why}")
        pytest.skip(why)
    out = tmp_path_factory.mktemp("docs_html")
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
           "-d", str(out / ".doctrees"), str(DOCS), str(out)]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"sphinx-build failed:\n{proc.stdout}\n{proc.stderr}"
    return out


def _text(site: Path, page: str) -> str:
    path = site / page
    assert path.is_file(), f"{page} was not built"
    return path.read_text(encoding="utf-8")


@pytest.mark.parametrize("page, needles", [
    ("index.html", ["snapping estimate --chi 0.25 --links 229 --length 1.022 --mass 0.0208", "pip install -e",
                    "arXiv:2206.07864"]),
    ("guide/estimate.html", ["design_estimate", "sigma_N", "--separation", "--links"]),
    ("guide/design.html", ["snapping design --max-tension", "admissible", "bench_table.py", "computed_estimate"]),
    ("api/table.html", ['id="snapping.table.lookup"', 'id="snapping.table.build.build"']),
    ("api/design.html", ['id="snapping.design.design"', 'id="snapping.design.computed_estimate"']),
    ("guide/simulate.html", ["snapping simulate --chi 0.25 --N 200 --method fast -o run.nc", "figures.profiles",
                             "PinMotion.flick"]),
    ("guide/fit.html", ["snapping fit run.nc", "fit_run", "--plot"]),
    ("guide/sweep.html", ["LocalCluster", "Client", "scheduler=client", "--scheduler tcp://", "run_sweep"]),
    ("guide/reproduce.html", ["snapping reproduce --quick -o paper_quick", "REPORT.md"]),
    ("guide/converge.html", ["snapping converge --chi 0.25", "converge(0.25", "order", "converge.png"]),
    ("guide/animate.html", ["snapping plot run.nc -o run.png", "--frames 60", "figures.overview", "plot.png"]),
    ("conventions.html", ["sqrt(L/g)", "M g", 'chords="exact"', "max_link_error",
                          "link-angle form", "position form", "methods_and_chords.py", "19.437688"]),
    ("architecture.html", ["The run Dataset", "METHODS", "arXiv:2206.07864"]),
    ("cli.html", ["usage: snapping [-h]", "usage: snapping simulate", "usage: snapping sweep", "--scheduler",
                  "usage: snapping converge", "usage: snapping reproduce"]),
    ("api/simulate.html", ['id="snapping.simulate.run"', 'id="snapping.simulate.Problem"',
                           'id="snapping.simulate.run_ensemble"', 'id="snapping.simulate.SimulationError"']),
    ("api/estimates.html", ['id="snapping.estimates.design_estimate"', "Parameters"]),
    ("notebooks/quickstart.html", ["snapping quickstart", "design_estimate"]),
    ("notebooks/paper_tour.html", ["check_printed_equations"]),
    ("notebooks/general_chains.html", ["Links.taper"]),
    ("benchmarks.html", ["bench_methods", "euler-richardson", "dop853"]),
    ("reproduction/REPORT.html", ["reproduction of the paper", "fig3_maxima.png"]),
    ("changelog.html", ["Unreleased", "0.1.0"]),
])
def test_page_says(site, page, needles):
    raw = _text(site, page)
    text = html.unescape(re.sub(r"<[^>]+>", "", raw))  # the words, without the code highlighting's tags
    missing = [n for n in needles if n not in raw and n not in text]
    assert not missing, f"{page} lacks {missing}"


def test_report_figures_are_copied(site):
    figures = sorted(p.name for p in (DOCS / "reproduction" / "figures").glob("*.png"))
    assert figures
    images = site / "_images"
    assert all((images / name).is_file() for name in figures)


def test_cli_page_is_the_parsers_help(site):
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        from snapping_cli import help_text
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    text = html.unescape(re.sub(r"<[^>]+>", "", _text(site, "cli.html")))
    for command in (None, "ideal", "estimate", "design", "simulate", "sweep", "fit", "converge", "reproduce", "plot",
                    "animate"):
        assert help_text(command).strip() in text, command


def test_referenced_names_are_documented(site):
    """Every snapping name a hand-written page links to has an entry in the API pages."""
    ids = set()
    for page in (site / "api").glob("*.html"):
        ids |= set(re.findall(r'id="(snapping[\w.]*)"', page.read_text(encoding="utf-8")))
    ids |= {m.removeprefix("module-") for page in (site / "api").glob("*.html")
            for m in re.findall(r'id="(module-snapping[\w.]*)"', page.read_text(encoding="utf-8"))}
    for page in PAGES:
        for name in ROLE.findall(page.read_text(encoding="utf-8")):
            assert name in ids, f"{page.name} refers to {name}, which the API reference does not document"


# ------------------------------------------------------------ no Sphinx needed
def test_referenced_names_exist():
    """The pages' {func}/{class}/... references name real objects of the package."""
    for page in PAGES:
        for name in ROLE.findall(page.read_text(encoding="utf-8")):
            parts = name.split(".")
            for i in range(len(parts), 0, -1):  # the longest importable module, then attributes
                try:
                    obj = importlib.import_module(".".join(parts[:i]))
                    break
                except ImportError:
                    continue
            for attr in parts[i:]:
                assert hasattr(obj, attr), f"{page.name}: {name} does not exist"
                obj = getattr(obj, attr)


def test_metadata_files():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert meta["project"]["license"]["text"] == "MIT"
    assert (ROOT / "LICENSE").read_text().startswith("MIT License\n\nCopyright (c) 2026 snapping developers")
    assert "py.typed" in meta["tool"]["setuptools"]["package-data"]["snapping"]
    assert (ROOT / "src" / "snapping" / "py.typed").is_file()
    assert {"sphinx", "numpydoc", "myst-nb", "furo"} <= {re.split(r"[<>=\[ ]", d)[0]
                                                        for d in meta["project"]["optional-dependencies"]["docs"]}
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["license"] == "MIT"
    assert cff["version"] == meta["project"]["version"]
    paper = cff["preferred-citation"]
    assert [a["family-names"] for a in paper["authors"]] == ["Dehadrai", "Hanna"]
    assert paper["identifiers"][0]["value"] == "arXiv:2206.07864"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in changelog and f"## [{meta['project']['version']}]" in changelog
