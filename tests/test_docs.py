"""The documentation site builds without a warning, and its generated tables are complete.

One build (module fixture) of a copy of ``docs/`` and ``examples/`` into a
temporary directory, as ``make docs`` builds it but with warnings as errors
(``-W --keep-going``), nitpicky (``-n``: a cross-reference to a target that
does not exist is a warning, so a broken reference fails) and without running
the gallery's scripts (``-D plot_gallery=0``: they take minutes; ``make docs``
runs them).  The file-format tables are made from the model classes' parameter
declarations at build time; the tests check that every declared key of every
registered model is in them, and every public name has its API page.
"""

from __future__ import annotations

import html
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

import polind
from polind.models import MODEL_TYPES
from polind.models.params import Table

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.filterwarnings("ignore")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """Build the site once; return ``(html directory, build log, seconds)``."""
    work = tmp_path_factory.mktemp("docs")
    generated = shutil.ignore_patterns("_build", "generated", "auto_examples", "__pycache__")
    shutil.copytree(ROOT / "docs", work / "docs", ignore=generated)
    shutil.copytree(ROOT / "examples", work / "examples",
                    ignore=shutil.ignore_patterns("__pycache__", "*.png", "*.parquet"))
    shutil.copy(ROOT / "LICENSE", work / "LICENSE")
    out = work / "html"
    # One Sphinx process (-j 1): beside the other xdist worker on two cores, parallel
    # reading only adds processes (29.5 CPU-s with -j 2, 26.4 to 27.5 with -j 1).
    command = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-n",
               "-q", "-j", "1", "-D", "plot_gallery=0", "-d", str(work / "doctrees"),
               str(work / "docs"), str(out)]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, cwd=work, timeout=900)
    seconds = time.perf_counter() - started
    log = done.stdout + done.stderr
    assert done.returncode == 0, f"the documentation build failed ({seconds:.0f} s):\n{log}"
    return out, log, seconds


def test_the_site_builds_without_warnings(site):
    out, log, _ = site
    assert "WARNING" not in log and "ERROR" not in log, log
    for page in ("index.html", "formats.html", "cli.html", "api/index.html",
                 "guide/pol_ind.html", "auto_examples/index.html", "license.html"):
        assert (out / page).is_file(), page


def _cell_text(cell: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", cell)).strip()


def _documented_keys(page: str, model_type: str) -> set[str]:
    """The dotted keys in the first column of a model's table on formats.html."""
    found = re.search(rf'<table class="[^"]*\bpolind-model-{re.escape(model_type)}\b[^"]*">'
                      r"(.*?)</table>", page, re.S)
    assert found, f"formats.html has no table of the {model_type} model"
    keys = set()
    for row in re.findall(r"<tr[^>]*>(.*?)</tr>", found.group(1), re.S):
        cells = re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)
        if not cells:
            continue                               # the header row
        text = _cell_text(cells[0])
        nested = re.fullmatch(r"(\w+) \(in \[model\.([\w.]+)\]\)", text)
        table = re.fullmatch(r"\[model\.([\w.]+)\]", text)
        if nested:
            keys.add(f"{nested.group(2)}.{nested.group(1)}")
        elif table:
            keys.add(table.group(1))
        else:
            keys.add(text)
    return keys


def _declared_keys(entries, prefix=""):
    for entry in entries:
        yield prefix + entry.key
        if isinstance(entry, Table):
            yield from _declared_keys(entry.entries, prefix + entry.key + ".")


@pytest.mark.parametrize("model_type", sorted(MODEL_TYPES))
def test_every_declared_key_is_in_the_file_format_tables(site, model_type):
    out, _, _ = site
    page = (out / "formats.html").read_text(encoding="utf-8")
    declared = set(_declared_keys(MODEL_TYPES[model_type].parameters))
    documented = _documented_keys(page, model_type)
    assert declared - documented == set(), f"{model_type}: keys missing from formats.html"
    assert documented - declared == set(), f"{model_type}: keys documented but not declared"


def test_the_key_table_reader_sees_a_missing_key(site):
    """The check above would notice a key left out of a table (it reads what it claims)."""
    out, _, _ = site
    page = (out / "formats.html").read_text(encoding="utf-8")
    cut = re.sub(r"<tr[^>]*>\s*<td[^>]*><p><code[^>]*><span[^>]*>attraction</span>"
                 r".*?</tr>", "", page, count=1, flags=re.S)
    assert "attraction" in _documented_keys(page, "gms")
    assert "attraction" not in _documented_keys(cut, "gms")


def test_every_public_name_has_an_api_page(site):
    out, _, _ = site
    for name in polind.__all__:
        assert (out / "api" / "generated" / f"polind.{name}.html").is_file(), name


def test_the_readme_model_table_says_what_the_models_say():
    """Each row of the README's table of models is what that model says of itself (its
    ``form`` and ``purpose``), in registration order.  The documentation's tables list
    every registered model by themselves; the README shows polind's own."""
    from polind.models import MODEL_TYPES

    readme = (ROOT / "README.md").read_text().splitlines()
    start = readme.index("| type | model | use it for |")
    rows = []
    for line in readme[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append(line)
    listed = [row.split("`")[1] for row in rows]
    assert listed == [name for name in MODEL_TYPES if name in listed] and len(listed) >= 8
    expected = [f"| `{name}` | {MODEL_TYPES[name].form} | {MODEL_TYPES[name].purpose} |"
                for name in listed]
    assert rows == expected, "\n".join(expected)


def test_no_page_shows_a_path_of_the_machine_that_built_it(site):
    # A value computed from __file__ (polind.kernels.cache.PACKAGE_DIR) printed the
    # builder's checkout into the API pages.
    out, _, _ = site
    here = str(Path(polind.__file__).resolve().parents[2])
    shown = [page.name for page in out.rglob("*.html") if here in page.read_text()]
    assert not shown, f"{here} appears in {shown}"


@pytest.mark.parametrize("script", sorted(path.name for path in (ROOT / "examples").glob("*.py")))
def test_every_example_imports(script):
    # The site's build here does not run the gallery (make docs does): at least every
    # script's imports and module-level tables must still resolve (two examples once
    # imported a name that had moved, or unpacked a dict whose values had changed).
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"example_{script[:-3]}",
                                                  ROOT / "examples" / script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert callable(getattr(module, "main", None)), f"{script} has no main()"
