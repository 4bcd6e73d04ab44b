"""The manual (README.md and docs/*.md) against the code it describes.

Checked: the pages' length (a manual, not a notebook: every page under 6000 words, all under 25 000, counted
as ``wc -w`` counts), no date stamps, and that everything the manual tells a user to type or open exists:
each ``python -m bridge.<module>`` command names a module of the package, options its parser has and
scenarios that are shipped; each ``python tools/<tool>.py`` command a tool that exists with the options it
names; each file path and each link (with its section, where it names one) a file and a section that are
there.  Each checker is also run on a small bad example, so that every test can fail.  Seconds: no CFD, no
network; the only subprocesses are one ``--help`` per command-line module.
"""

from __future__ import annotations

import functools
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
README = REPO / "README.md"
PAGE_WORDS, TOTAL_WORDS = 6000, 25000
DATE_STAMP = re.compile(r"20\d\d-\d\d-\d\d")
FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.M | re.S)
BRIDGE_COMMAND = re.compile(r"python3? -m bridge\.([\w.]+)(.*)")
TOOL_COMMAND = re.compile(r"python3? (tools/[\w-]+\.py)(.*)")
PATH = re.compile(r"(?<![\w./-])((?:bridge|kernels|tests|tools)/[\w./-]+\.py|scenarios/[\w./-]+\.(?:toml|csv)"
                  r"|docs/[\w./-]+\.(?:md|png))")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
SECTION = re.compile(r"\[[^\]]*\]\(([\w./-]+\.md)\),? \"([^\"]+)\"")


def manual() -> list[Path]:
    return [README, *sorted(DOCS.glob("*.md"))]


# ------------------------------------------------------------------------------------------- the checkers
def word_count(text: str) -> int:
    """Words as ``wc -w`` counts them: runs of characters between whitespace."""
    return len(text.split())


def size_problems(pages: dict[str, str]) -> list[str]:
    """Pages over PAGE_WORDS, and the whole over TOTAL_WORDS."""
    words = {name: word_count(text) for name, text in pages.items()}
    problems = [f"{name}: {n} words (at most {PAGE_WORDS})" for name, n in words.items() if n > PAGE_WORDS]
    if sum(words.values()) >= TOTAL_WORDS:
        problems.append(f"all pages: {sum(words.values())} words (under {TOTAL_WORDS})")
    return problems


def date_problems(text: str) -> list[str]:
    return [f"date stamp {m.group()}" for m in DATE_STAMP.finditer(text)]


def code_of(text: str) -> list[str]:
    """What a reader may type: each line of a fenced block (backslash continuations joined) and each inline
    code span."""
    pieces = []
    for block in FENCE.findall(text):
        pieces += block.replace("\\\n", " ").splitlines()
    pieces += re.findall(r"`([^`]+)`", FENCE.sub("", text))
    return [" ".join(p.split()) for p in pieces]


def _tokens(rest: str) -> list[str]:
    """The arguments of one command: up to a comment or the next command of a shell line."""
    rest = re.split(r"\s#|&&|;|\|\|", rest)[0]
    try:
        return shlex.split(rest)
    except ValueError:
        return rest.split()


@functools.cache
def cli_options(module: str) -> dict[str, bool] | None:
    """``{option: takes a value}`` of ``python -m bridge.<module>``, from its ``--help``; None if the module
    has no command line."""
    proc = subprocess.run([sys.executable, "-m", f"bridge.{module}", "--help"], capture_output=True, text=True,
                          cwd=REPO, timeout=300)
    if proc.returncode != 0:
        return None
    options: dict[str, bool] = {}
    for line in proc.stdout.splitlines():
        m = re.match(r"^  (-\S.*?)(?:\s{2,}|$)", line)
        if m:
            for alias in m.group(1).split(", "):
                name, _, metavar = alias.partition(" ")
                options[name] = bool(metavar)
    return options


def _placeholder(token: str) -> bool:
    """NAME_OR_PATH, SCENARIO, ..., <name>: words the reader replaces."""
    return token.isupper() or "..." in token or "<" in token or not token


def _scenario_problem(token: str) -> str | None:
    if token.endswith(".toml") or "/" in token:       # a file of the reader's, unless it names a shipped one
        if token.startswith("scenarios/") and not (REPO / token).exists():
            return f"no scenario file {token}"
        return None
    if not (REPO / "scenarios" / f"{token}.toml").exists():
        return f"no shipped scenario {token!r} (scenarios/{token}.toml)"
    return None


def command_problems(text: str) -> list[str]:
    """Commands in code that name a module, option, scenario or tool that does not exist."""
    problems = []
    for code in code_of(text):
        for m in BRIDGE_COMMAND.finditer(code):
            module, where = m.group(1), f"`python -m bridge.{m.group(1)}{m.group(2)[:60]}`"
            if not (REPO / "bridge" / f"{module.replace('.', '/')}.py").exists():
                problems.append(f"{where}: no module bridge/{module.replace('.', '/')}.py")
                continue
            options = cli_options(module)
            if options is None:
                problems.append(f"{where}: bridge.{module} has no command line (--help fails)")
                continue
            tokens, i = _tokens(m.group(2)), 0
            while i < len(tokens):
                bracketed, token = tokens[i].startswith("["), tokens[i].strip("[]")
                i += 1
                if token.startswith("-"):
                    name, has_value = token.partition("=")[0], "=" in token
                    if name not in options:
                        problems.append(f"{where}: bridge.{module} has no option {name}")
                    elif options[name] and not has_value:
                        i += 1                             # its value
                elif not (bracketed or _placeholder(token)) and module in ("scenario", "sweep"):
                    problem = _scenario_problem(token)
                    if problem:
                        problems.append(f"{where}: {problem}")
        for m in TOOL_COMMAND.finditer(code):
            tool, where = REPO / m.group(1), f"`python {m.group(1)}`"
            if not tool.exists():
                problems.append(f"{where}: no such tool")
                continue
            source = tool.read_text(encoding="utf-8")
            for token in _tokens(m.group(2)):
                name = token.strip("[]()").partition("=")[0]
                if name.startswith("--") and f'"{name}"' not in source:
                    problems.append(f"{where}: the tool has no option {name}")
    return problems


def path_problems(text: str) -> list[str]:
    """Repository paths (tools, scenarios, modules, pages, images) named anywhere that do not exist."""
    return [f"no file {p}" for p in sorted(set(PATH.findall(text))) if not (REPO / p).exists()]


def _sections(page: Path) -> list[str]:
    """A page's headings and bold labels: what a link or a quoted section name may point at."""
    text = page.read_text(encoding="utf-8")
    return [line.lstrip("#").strip() for line in text.splitlines() if line.startswith("#")] \
        + re.findall(r"\*\*(.+?)\*\*", text)


def _anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def link_problems(text: str, folder: Path) -> list[str]:
    """Links to files or anchors that are not there, and quoted section names (``[page](page.md),
    "Section"``) that the page does not have."""
    problems = []
    for target in LINK.findall(text):
        if re.match(r"[a-z]+:", target):
            continue                                        # https:, mailto:
        file, _, anchor = target.partition("#")
        page = (folder / file) if file else None
        if page is not None and not page.exists():
            problems.append(f"link to {target}: no such file")
        elif anchor and page is not None and page.suffix == ".md" \
                and anchor not in {_anchor(s) for s in _sections(page)}:
            problems.append(f"link to {target}: no such section")
    for file, name in SECTION.findall(text):
        page, name = folder / file, " ".join(name.split())     # a name may run over a line break
        if page.exists() and not any(name in s for s in _sections(page)):
            problems.append(f'{file}, "{name}": no such section')
    return problems


# ------------------------------------------------------------------------------------------- the manual
def test_pages_are_a_manual_not_a_notebook():
    pages = {p.name: p.read_text(encoding="utf-8") for p in DOCS.glob("*.md")}
    assert pages and not size_problems(pages), size_problems(pages)
    assert size_problems({"long.md": "word " * (PAGE_WORDS + 1)})
    assert size_problems({f"{i}.md": "word " * 5000 for i in range(5)})       # 25 000 in all
    assert word_count("one two\nthree\t| four |") == 6


def test_no_date_stamps():
    found = {p.name: date_problems(p.read_text(encoding="utf-8")) for p in manual()}
    assert not any(found.values()), found
    assert date_problems("measured on 2026-12-04, evening")


def test_every_command_names_what_exists():
    found = {p.name: command_problems(p.read_text(encoding="utf-8")) for p in manual()}
    assert not any(found.values()), found
    good = ("`python -m bridge.scenario great_belt model_a --quality standard --overwrite`\n"
            "```\npython -m bridge.sweep my_bridge.toml --main-span 1624,2000 \\\n  --vary girder.width_m=30,31\n```\n"
            "`python tools/bench_cfd.py --sizes 1024x512`, `python -m bridge.scenario NAME_OR_PATH [options]`")
    assert command_problems(good) == []
    for bad in ("`python -m bridge.no_such_module great_belt`",
                "`python -m bridge.scenario great_belt --no-such-option`",
                "```\npython -m bridge.scenario great_belt \\\n  --quality standard no_such_bridge\n```",
                "`python -m bridge.sweep no_such_bridge --main-span 2000`",
                "`python -m bridge.scenario scenarios/no_such_bridge.toml`",
                "`python tools/no_such_tool.py`",
                "`python tools/bench_cfd.py --no-such-option 3`"):
        assert command_problems(bad), bad


def test_every_file_and_link_exists():
    found = {p.name: path_problems(p.read_text(encoding="utf-8")) + link_problems(p.read_text(encoding="utf-8"),
                                                                                   p.parent)
             for p in manual()}
    assert not any(found.values()), found
    assert not link_problems('[the presets](aero.md#presets), [flutter.md](flutter.md), "Multimode p-k"', DOCS)
    for bad in ("see tools/no_such_tool.py", "the file scenarios/no_such_bridge.toml", "docs/no_such_page.md"):
        assert path_problems(bad), bad
    for bad in ("[a page](no_such_page.md)", "[a section](aero.md#no-such-section)",
                '[flutter.md](flutter.md), "No such section"'):
        assert link_problems(bad, DOCS), bad


@pytest.mark.parametrize("page", ["aero.md", "cfd.md", "flutter.md", "results.md", "validation.md",
                                  "performance.md", "structure.md", "cable.md", "own_bridge.md",
                                  "reference_cases.md", "thesis_errata.md", "warp_cpu.md", "equations.md",
                                  "guide.md", "glossary.md"])
def test_the_pages_code_and_tests_point_at_exist(page):
    assert (DOCS / page).exists(), page
