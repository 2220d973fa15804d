"""One command surface for people and CI: ``nox -s <session>``.

Sessions
--------
lint      ruff check, ruff format --check, mypy (strict) on ``src``
tests     the default test run: ``pytest -m "not slow"`` (extra arguments go to pytest)
slow      the long sweeps: ``pytest -m slow``
docs      ``mkdocs build --strict`` (``-- --placeholders`` stands in for nav pages not written yet)
bench     runs every ``benchmarks/*.py`` script and prints its Markdown report
examples  runs every ``examples/*.py`` script

Every session installs the project with ``-c constraints.txt``: torch and litellm are pinned there
(an unpinned torch downloads a multi-GB CUDA build; see the comments in ``constraints.txt``).
Virtual environments are reused between runs; ``nox -R -s tests`` also skips the reinstall.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import nox

nox.options.default_venv_backend = "venv"
nox.options.reuse_venv = "yes"
nox.options.sessions = ["lint", "tests"]
nox.options.error_on_missing_interpreters = True

ROOT = Path(__file__).resolve().parent
CONSTRAINTS = str(ROOT / "constraints.txt")

# Read before any import of litellm (otherwise it fetches a cost map from the network at import) and
# before matplotlib picks an interactive backend.
ENV = {"LITELLM_LOCAL_MODEL_COST_MAP": "True", "MPLBACKEND": "Agg", "NO_MKDOCS_2_WARNING": "1"}

PLACEHOLDER_MARK = "<!-- audere: placeholder written by `nox -s docs -- --placeholders`; not committed -->"


def _install(session: nox.Session, extras: str) -> None:
    """Install the project in editable mode with ``extras``, always under the constraints file."""
    session.install("-c", CONSTRAINTS, "-e", f".[{extras}]")


def _scripts(folder: str) -> list[Path]:
    """Return the runnable scripts of ``folder`` (``*.py`` not starting with ``_``), sorted."""
    return sorted(p for p in (ROOT / folder).glob("*.py") if not p.name.startswith("_"))


@nox.session
def lint(session: nox.Session) -> None:
    """Run ruff (lint and format check) on the whole tree and mypy (strict) on ``src``."""
    # The backends are installed too so that mypy sees the same imports as in a development install.
    _install(session, "all,lint")
    session.run("ruff", "check", ".")
    session.run("ruff", "format", "--check", ".")
    session.run("mypy", "src")


@nox.session
def tests(session: nox.Session) -> None:
    """Run the default test suite, ``pytest -m "not slow"``; extra arguments are passed to pytest."""
    _install(session, "all,test")
    session.run("python", "-m", "pytest", "-m", "not slow", *session.posargs, env=ENV)


@nox.session
def slow(session: nox.Session) -> None:
    """Run only the tests marked ``slow`` (long sweeps); extra arguments are passed to pytest."""
    _install(session, "all,test")
    session.run("python", "-m", "pytest", "-m", "slow", *session.posargs, env=ENV)


def _nav_pages() -> list[Path]:
    """Return the Markdown pages named in the ``nav`` of ``mkdocs.yml`` (read without a YAML parser)."""
    text = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    return [ROOT / "docs" / m.group(1) for m in re.finditer(r"^\s*-\s*[^:\n]+:\s*(\S+\.md)\s*$", text, re.M)]


@nox.session
def docs(session: nox.Session) -> None:
    """Build the documentation with ``mkdocs build --strict`` into ``site/``.

    ``nox -s docs -- --placeholders`` writes a stub for every nav page that does not exist yet, builds,
    and removes those stubs again (only the ones still holding the stub text). Other arguments go to
    ``mkdocs build``.
    """
    # ruff too: mkdocstrings formats the separate signatures with it.
    _install(session, "docs,lint")
    args = list(session.posargs)
    written: list[Path] = []
    if "--placeholders" in args:
        args.remove("--placeholders")
        for page in _nav_pages():
            if not page.exists():
                page.write_text(f"# {page.stem.title()}\n\n{PLACEHOLDER_MARK}\n\nNot written yet.\n")
                written.append(page)
                session.warn(f"placeholder for missing page {page.relative_to(ROOT)}")
    try:
        session.run("mkdocs", "build", "--strict", *args, env=ENV)
    finally:
        for page in written:
            if page.exists() and PLACEHOLDER_MARK in page.read_text(encoding="utf-8"):
                page.unlink()


@nox.session
def bench(session: nox.Session) -> None:
    """Run every ``benchmarks/*.py`` script; each prints a Markdown table, shown here in turn."""
    _install(session, "all")
    scripts = _scripts("benchmarks")
    if not scripts:
        session.skip("no benchmarks/*.py scripts yet")
    for script in scripts:
        session.log(f"## {script.relative_to(ROOT)}")
        session.run("python", str(script), *session.posargs, env=ENV)


@nox.session
def examples(session: nox.Session) -> None:
    """Run every ``examples/*.py`` script from a scratch directory, with timings."""
    _install(session, "all")
    scripts = _scripts("examples")
    if not scripts:
        session.skip("no examples/*.py scripts yet")
    scratch = session.create_tmp()  # examples must not write into the repository
    timings: list[tuple[str, float]] = []
    with session.chdir(scratch):
        for script in scripts:
            start = time.perf_counter()
            session.run("python", str(script), env=ENV)
            timings.append((script.name, time.perf_counter() - start))
    for name, seconds in timings:
        session.log(f"{name}: {seconds:.1f} s")
