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
