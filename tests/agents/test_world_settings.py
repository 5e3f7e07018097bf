"""Each scenario family's world settings are a declared section: a misspelt setting in
a world file stops ``petriflow run`` before anything runs, with the world file's line,
a close match and exit code 2."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

pytest.importorskip("pybullet")

from petriflow.cli import main

NETS = Path(__file__).resolve().parents[2] / "nets"


@pytest.mark.parametrize("net, world, setting, typo, section", [
    ("smart/smart.yaml", "smart/world.yaml", "floor", "flor", "smart"),
    ("examples/inspection.yaml", "examples/inspection-world.yaml", "floor", "flooor", "smart"),
    ("comm/comm-decentralised-2.yaml", "comm/world.yaml", "rows", "rowz", "maze"),
    ("swarm/swarm-3.yaml", "swarm/world.yaml", "cell", "cel", "maze"),
    ("slam/slam-decentralised.yaml", "slam/world.yaml", "half_width", "half_widht", "slam"),
])
def test_a_misspelt_world_setting_fails_at_its_line(tmp_path, capsys, net, world, setting, typo, section):
    text = (NETS / world).read_text(encoding="utf-8")
    lines = text.splitlines()
    found = [i for i, line in enumerate(lines) if re.match(rf"\s+{setting}:", line)]
    assert found, f"{world} has no {setting!r} to misspell"
    lines[found[0]] = lines[found[0]].replace(f"{setting}:", f"{typo}:", 1)
    bad = tmp_path / "world.yaml"
    bad.write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert main(["run", str(NETS / net), "--world", str(bad), "--until", "0"]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith(f"petriflow: {bad}:{found[0] + 1}: 'meta.{section}': unknown setting {typo!r}"
                            f" (did you mean {setting!r}?)"), error
    assert "Traceback" not in error
