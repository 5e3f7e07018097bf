"""The examples in README.md and docs/ run as written, and the docs agree with the code."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys

import pytest

from petriflow.io.yaml import loads_net
from tests.conftest import REPO

DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def documented_tests():
    """Python blocks that define a pytest test, by document."""
    found = []
    for document in DOCUMENTS:
        for block in re.findall(r"```python\n(.*?)```", document.read_text(encoding="utf-8"), re.S):
            if re.search(r"^def test_", block, re.M):
                found.append((document.name, block))
    return found


@pytest.mark.parametrize("document, block", documented_tests(), ids=lambda v: v if v.endswith(".md") else "")
def test_a_documented_test_runs_outside_the_repository(tmp_path, document, block):
    """Written into an empty folder and run by pytest there, the documented test passes."""
    (tmp_path / "test_documented.py").write_text(block, encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_documented.py"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


#: Documents whose Python examples are run as written (besides the test examples above).
RUN_AS_WRITTEN = [REPO / "README.md", REPO / "docs" / "api.md"]


def blocks(document, language):
    """The fenced blocks of one language in a document, in order."""
    return re.findall(rf"```{language}\n(.*?)```", document.read_text(encoding="utf-8"), re.S)


def named_file(block):
    """The path a block stands for when its first line is a comment naming a file
    (``# charging/run.yaml``), else ``None``."""
    match = re.match(r"# ([\w./-]+\.(?:py|yaml))\n", block)
    return match.group(1) if match else None


def readme_folder(folder):
    """``folder`` made like the repository root for README's examples: the files README
    shows written into it, and ``nets`` the repository's nets."""
    for document in RUN_AS_WRITTEN:
        for block in blocks(document, "python") + blocks(document, "yaml"):
            if named_file(block):
                (folder / named_file(block)).parent.mkdir(parents=True, exist_ok=True)
                (folder / named_file(block)).write_text(block, encoding="utf-8")
    (folder / "nets").symlink_to(REPO / "nets", target_is_directory=True)
    return folder


def python_examples():
    return [pytest.param(block, id=f"{document.name}-{number}")
            for document in RUN_AS_WRITTEN
            for number, block in enumerate(blocks(document, "python"))
            if not named_file(block) and not re.search(r"^def test_", block, re.M)]


@pytest.mark.parametrize("block", python_examples())
def test_a_python_example_runs_as_written(tmp_path, block):
    """Each Python example of README.md and docs/api.md runs in a folder that holds what
    README says to write (and the shipped nets), printing what its comments say."""
    done = subprocess.run([sys.executable, "-c", block], cwd=readme_folder(tmp_path), capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    shown = [re.search(r"#\s*(.*)$", line).group(1) for line in block.splitlines()
             if line.startswith("print(") and re.search(r"#\s*[\[{'\w]", line)]
    printed = done.stdout.splitlines()
    for expected in shown:
        if not expected.startswith(("a ", "the ")):  # a comment that describes, not shows
            assert expected in printed, (expected, printed)


def test_the_readme_action_of_ones_own_runs_from_the_command_line(tmp_path):
    """``petriflow run charging/net.yaml``, as README shows it, finds the user's module
    through the run configuration's ``actions:`` and prints what README says."""
    folder = readme_folder(tmp_path)
    commands = [line for block in blocks(REPO / "README.md", "bash") for line in block.splitlines()
                if line.startswith("petriflow run charging/")]
    assert commands, "README shows no run of its own-action example"
    for line in commands:
        command, _, shown = line.partition("#")
        done = subprocess.run([sys.executable, "-m", "petriflow.cli", *command.split()[1:]], cwd=folder,
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
        assert done.stdout.startswith(shown.strip().split("...")[0]), done.stdout


def test_every_net_readme_shows_loads():
    """Each YAML block of README.md that is a net (``petriflow: 1``) reads as one."""
    nets = [block for block in blocks(REPO / "README.md", "yaml") if "\npetriflow: 1\n" in "\n" + block]
    assert nets  # the README shows at least one net
    for block in nets:
        assert loads_net(block).transitions


def test_the_api_page_lists_exactly_the_stable_names():
    """docs/api.md's table of stable names is ``petriflow.__all__``, and its table of
    names that left the top level matches where the top level says they went."""
    import petriflow

    page = (REPO / "docs" / "api.md").read_text(encoding="utf-8")
    stable = page.split("## Stable", 1)[1].split("\n## ", 1)[0]
    listed = re.findall(r"^\| `(\w+)` \|", stable, re.M)
    assert sorted(listed) == sorted(petriflow.__all__) and len(set(listed)) == len(listed)
    moved = {name: module for module, names in re.findall(r"^\| `(petriflow[\w.]*)` \| (`.*`) \|$", page, re.M)
             for name in re.findall(r"`(\w+)`", names)}
    assert moved == petriflow._MOVED


def test_every_module_the_api_page_names_exists():
    """Each ``petriflow.x.y`` module docs/api.md names imports (the listed names of a
    module stay where the page says)."""
    page = (REPO / "docs" / "api.md").read_text(encoding="utf-8")
    modules = set(re.findall(r"`(petriflow(?:\.[a-z_]+)+)`", page)) - {"petriflow.agents", "petriflow.vision"}
    for module in sorted(modules):
        try:
            importlib.import_module(module)
        except ModuleNotFoundError:
            parent, _, name = module.rpartition(".")  # a name inside a module, e.g. petriflow.examples.path
            assert hasattr(importlib.import_module(parent), name), module


def headings(document):
    """The anchors of a Markdown document's headings, as GitHub makes them."""
    text = re.sub(r"```.*?```", "", document.read_text(encoding="utf-8"), flags=re.S)
    return {re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")
            for title in re.findall(r"^#+\s+(.*)$", text, re.M)}


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda d: d.name)
def test_every_link_of_the_docs_reaches_a_file_and_heading(document):
    """A relative link in README.md or docs/ names a file that exists and, for a
    Markdown file, a heading it has."""
    text = re.sub(r"```.*?```", "", document.read_text(encoding="utf-8"), flags=re.S)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"^[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        linked = (document.parent / path) if path else document
        assert linked.exists(), f"{document.name}: {target}"
        if anchor and linked.suffix == ".md":
            assert anchor in headings(linked), f"{document.name}: {target}"
