"""The package list in pyproject.toml covers every folder that ships files, so an install
gets every net, world and URDF, and setuptools warns about none of them."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_folder_with_files_is_a_listed_package():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    missing = []
    for package, folder in config["package-dir"].items():
        for path in sorted((ROOT / folder).rglob("*")):
            if not path.is_dir() or "__pycache__" in path.parts or path.name.startswith("."):
                continue
            if not any(f.is_file() and not f.name.startswith(".") for f in path.iterdir()):
                continue
            name = ".".join([package, *path.relative_to(ROOT / folder).parts])
            if name not in listed:
                missing.append(name)
    assert not missing, f"add to [tool.setuptools] packages in pyproject.toml: {missing}"


def test_a_quiet_test_run_names_its_random_order_seed(tmp_path):
    """``scripts/test.sh`` runs pytest with ``-q``, which hides the header where
    pytest-randomly names its seed: the seed comes in the last lines instead."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "randomly", "--randomly-seed=7",
                           str(ROOT / "tests" / "test_marking.py")], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:]
    assert "--randomly-seed=7" in done.stdout.splitlines()[-1]
