"""The repository stands alone: no file cites a path outside it, every ``docs/<file>.md#anchor``
cited in code, configs and docs names an existing heading, and every relative link in the
README and docs/ resolves (docs/architecture.md#conventions, "Citations")."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: What is checked: the library, configs, examples, tests, benchmarks, docs and the READMEs.
SCANNED = (
    "suspopt",
    "configs",
    "examples",
    "tests",
    "benchmarks",
    "docs",
    "README.md",
    "pyproject.toml",
)
#: Citations of files that live outside the repository (the character classes keep this file
#: from matching itself): the design notes, the list of the thesis's slips, the standards'
#: facts, the shared folder they sit in, and the slips list cited by its bare name.
OUTSIDE = re.compile(
    r"\b(?:DESIG[N]|ERRAT[A]|standard[s])\.md|\.\./share[d]|\breferenc[e]/\d{3}_"
    r"|\bERRAT[A]\b"
)
#: A cited docs page, optionally with an anchor: ``docs/thesis-slips.md#eq-2104``,
#: ``docs/guide/engines.md#the-rule-of-auto``.
DOCS_CITATION = re.compile(r"\bdocs/((?:[\w-]+/)*[\w-]+\.md)(?:#([\w-]+))?")
#: Folders of docs/ that the site's build writes (not sources).
BUILT = ("_build", "gallery", "generated")
#: A markdown link ``[text](target)``; images too.
MARKDOWN_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def _text_files() -> list[Path]:
    files = []
    for name in SCANNED:
        path = ROOT / name
        candidates = [path] if path.is_file() else sorted(path.rglob("*"))
        for file in candidates:
            built = file.is_relative_to(ROOT / "docs") and any(p in BUILT for p in file.parts)
            if file.is_file() and "__pycache__" not in file.parts and file.suffix != ".h5":
                if built:
                    continue
                try:
                    file.read_text(encoding="utf-8")
                except UnicodeDecodeError:
                    continue
                files.append(file)
    return files


def _docs_pages() -> list[Path]:
    """The Markdown pages of the documentation site (docs/, not what its build writes)."""
    pages = sorted((ROOT / "docs").rglob("*.md"))
    return [p for p in pages if not any(part in BUILT for part in p.relative_to(ROOT).parts)]


def _markdown_files() -> list[Path]:
    return [ROOT / "README.md", ROOT / "configs" / "README.md", *_docs_pages()]


def github_anchor(heading: str) -> str:
    """GitHub's anchor of a heading's text: markup and punctuation dropped (letters, digits,
    ``_``, ``-`` and spaces kept), lower case, each space a hyphen."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip())  # links: their text
    text = re.sub(r"[^\w\- ]", "", text.lower())
    return text.replace(" ", "-")


def _outside_code(lines: list[str]) -> list[tuple[int, str]]:
    """(line number, line) of the lines of a markdown file outside fenced code blocks."""
    kept, fenced = [], False
    for number, line in enumerate(lines, 1):
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced:
            kept.append((number, line))
    return kept


def anchors(markdown: Path) -> set[str]:
    """Every heading anchor of a markdown file, numbered ``-1``, ``-2`` ... when repeated."""
    seen: dict[str, int] = {}
    found = set()
    for _, line in _outside_code(markdown.read_text(encoding="utf-8").splitlines()):
        match = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if match:
            anchor = github_anchor(match.group(1))
            count = seen.get(anchor, 0)
            found.add(anchor if count == 0 else f"{anchor}-{count}")
            seen[anchor] = count + 1
    return found


def _links(markdown: Path) -> list[tuple[int, str]]:
    """(line, target) of the markdown links outside code blocks and inline code."""
    links = []
    for number, line in _outside_code(markdown.read_text(encoding="utf-8").splitlines()):
        prose = re.sub(r"`[^`]*`", "", line)
        links += [(number, target) for target in MARKDOWN_LINK.findall(prose)]
    return links


def _where(path: Path, number: int) -> str:
    return f"{path.relative_to(ROOT)}:{number}"


def test_heading_anchors_follow_github():
    assert github_anchor("Eq 2.104") == "eq-2104"
    assert github_anchor("Sec 2.5.1") == "sec-251"
    assert github_anchor("Bad input: what is checked") == "bad-input-what-is-checked"
    assert (
        github_anchor("`suspopt simulate CONFIG [-o OUT.h5]`") == "suspopt-simulate-config--o-outh5"
    )
    assert github_anchor("ISO 8608 road roughness") == "iso-8608-road-roughness"


def test_no_file_cites_a_path_outside_the_repository():
    """The design notes, the slips list and the standards' facts are docs/ pages now."""
    found = [
        f"{_where(file, n)}: {line.strip()}"
        for file in _text_files()
        for n, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not found, "cite docs/ instead:\n" + "\n".join(found)


def test_cited_docs_pages_and_anchors_exist():
    """Every ``docs/<file>.md#anchor`` in code, configs, tests, examples and docs."""
    pages = {page.relative_to(ROOT / "docs").as_posix(): anchors(page) for page in _docs_pages()}
    assert {"architecture.md", "thesis-slips.md", "iso-facts.md"} <= set(pages)
    broken, cited = [], 0
    for file in _text_files():
        for n, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
            for page, anchor in DOCS_CITATION.findall(line):
                cited += 1
                if page not in pages:
                    broken.append(f"{_where(file, n)}: no page docs/{page}")
                elif anchor and anchor not in pages[page]:
                    broken.append(f"{_where(file, n)}: no heading #{anchor} in docs/{page}")
    assert cited > 0
    assert not broken, "\n".join(broken)


@pytest.mark.parametrize("markdown", _markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(markdown):
    """Every relative link of the READMEs and docs/*.md names an existing file, and its
    ``#anchor`` (or a bare ``#anchor`` in the same file) an existing heading."""
    broken = []
    for n, target in _links(markdown):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        path_part, _, anchor = target.partition("#")
        path = (markdown.parent / path_part).resolve() if path_part else markdown
        if path.parent == ROOT / "docs" / "gallery" and path.stem == "index":
            path = ROOT / "examples" / "gallery"  # built from there by sphinx-gallery
        if not path.exists():
            broken.append(f"{_where(markdown, n)}: {target}: no such file")
        elif anchor and path.suffix == ".md" and anchor not in anchors(path):
            broken.append(f"{_where(markdown, n)}: {target}: no such heading")
    assert not broken, "\n".join(broken)


def test_readme_links_the_site_and_each_of_its_sections():
    """The README is the front door: it links the site's home and each section's first page
    (the sections are the entries of the home page's table of contents)."""
    readme = {target.partition("#")[0] for _, target in _links(ROOT / "README.md")}
    home = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    toc = home[home.index("```{toctree}") :].split("```")[1]
    entries = [e.strip() for e in toc.splitlines()[1:] if e.strip() and ":" not in e]
    sections = {"docs/index.md"}
    for entry in entries:
        source = ROOT / "docs" / f"{entry}.md"
        if source.exists():  # (the gallery's index is built from examples/gallery)
            sections.add(source.relative_to(ROOT).as_posix())
    assert sections <= readme, f"README links none of {sorted(sections - readme)}"
