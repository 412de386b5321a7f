"""References to the design notes in docs/ resolve: the files exist and the named sections too.

A reference is ``docs/<name>.md``, optionally followed on the same line by the headings of the
sections it means, each in double quotes after a comma: ``(docs/stack.md, "Seeding")`` or
``docs/mechanics.md, "Fixtures", "Membership table"``. A heading matches a Markdown heading line
(``#`` to ``######``) of that file with the same text. Notes kept outside the repository must not
be cited at all.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("planner", "mechanics", "tests", "pyproject.toml", "README.md")
TEXT_SUFFIXES = {".py", ".toml", ".md", ".txt", ".yaml", ".yml", ".cfg", ".ini", ""}

#: Names of notes that live outside the repository, built here so that this file does not cite them.
FORBIDDEN = ["STACK" + ".md", "MECHANICS" + ".md", ".." + "/shared"]

REFERENCE = re.compile(r'docs/([A-Za-z0-9_.-]+?\.md)((?:,[ \t]*"[^"\n]+")*)')
HEADING = re.compile(r'"([^"\n]+)"')
DANGLING = re.compile(r"docs/[A-Za-z0-9_.-]+?\.md,[ \t]*$", re.MULTILINE)


def scanned_files() -> list[Path]:
    """The tracked files under SCANNED (every file there when git is not available)."""
    try:
        out = subprocess.run(["git", "ls-files", "--", *SCANNED], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout
        files = [ROOT / line for line in out.splitlines() if line]
    except (OSError, subprocess.CalledProcessError):
        files = [p for name in SCANNED for p in ([ROOT / name] if (ROOT / name).is_file()
                                                  else (ROOT / name).rglob("*"))]
    return sorted(p for p in files if p.is_file() and p.suffix in TEXT_SUFFIXES)


def references(text: str) -> list[tuple[int, str, list[str]]]:
    """``(line, doc file name, [headings])`` for each reference in ``text``."""
    return [(text.count("\n", 0, m.start()) + 1, m.group(1), HEADING.findall(m.group(2)))
            for m in REFERENCE.finditer(text)]


def headings(doc: Path) -> set[str]:
    """The text of every Markdown heading of ``doc`` (outside fenced code)."""
    found, fenced = set(), False
    for line in doc.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and (m := re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)):
            found.add(m.group(1))
    return found


def problems(files: list[Path], docs: Path) -> list[str]:
    """Every broken or forbidden reference in ``files``, as ``path:line: what``."""
    out, cache = [], {}
    for path in files:
        if path.resolve() == Path(__file__).resolve():
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        where = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
        for name in FORBIDDEN:
            for m in re.finditer(re.escape(name), text):
                out.append(f"{where}:{text.count(chr(10), 0, m.start()) + 1}: cites {name}, not in the repository")
        for m in DANGLING.finditer(text):
            out.append(f"{where}:{text.count(chr(10), 0, m.start()) + 1}: keep a reference's headings on its line")
        for line, name, wanted in references(text):
            doc = docs / name
            if not doc.is_file():
                out.append(f"{where}:{line}: docs/{name} does not exist")
                continue
            if name not in cache:
                cache[name] = headings(doc)
            out += [f'{where}:{line}: docs/{name} has no heading "{h}"' for h in wanted if h not in cache[name]]
    return out


def test_references_resolve():
    files = scanned_files()
    assert any(p.suffix == ".py" for p in files)
    assert not problems(files, ROOT / "docs"), "\n".join(problems(files, ROOT / "docs"))


def test_the_code_cites_the_notes():
    cited = {name for path in scanned_files() if path.resolve() != Path(__file__).resolve()
             for _, name, _ in references(path.read_text(encoding="utf-8", errors="replace"))}
    assert {"stack.md", "mechanics.md"} <= cited


@pytest.mark.parametrize("text, complaint", [
    ('x = 1  # (docs/stack.md, "No such section")', 'has no heading "No such section"'),
    ("# see docs/nowhere.md", "docs/nowhere.md does not exist"),
    ("# see " + FORBIDDEN[0] + " §1", "not in the repository"),
    ("# see " + FORBIDDEN[2] + "/notes", "not in the repository"),
    ('"""Fixture A (docs/mechanics.md,\n"Fixtures")."""', "keep a reference's headings on its line"),
])
def test_broken_references_are_caught(tmp_path, text, complaint):
    source = tmp_path / "module.py"
    source.write_text(text + "\n")
    found = problems([source], ROOT / "docs")
    assert len(found) == 1 and complaint in found[0], found


def test_good_references_pass(tmp_path):
    source = tmp_path / "module.py"
    source.write_text('# (docs/stack.md, "Seeding") and docs/mechanics.md, "Fixtures", "Membership table"\n')
    assert problems([source], ROOT / "docs") == []
    assert references(source.read_text()) == [(1, "stack.md", ["Seeding"]),
                                              (1, "mechanics.md", ["Fixtures", "Membership table"])]
