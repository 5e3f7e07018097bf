"""``petriflow info --config RUN.yaml`` marks the subnets and transitions a ``bridge:`` puts on
remote agents (nothing connects: it only reads the configuration)."""

import json

from petriflow.cli import main

from tests.bridge.test_bridged_run import write


def test_info_shows_which_subnets_and_transitions_run_on_which_remote_agent(tmp_path, capsys):
    """One subnet on a remote agent, one local: the text and --json say which is which."""
    net = write(tmp_path, "mqtt", "tcp/127.0.0.1:1883")
    (tmp_path / "other.yaml").write_text((tmp_path / "run.yaml").read_text())
    (tmp_path / "run.yaml").unlink()  # the configuration is only the one given
    assert main(["info", str(net), "--config", str(tmp_path / "other.yaml")]) == 0
    text = capsys.readouterr().out
    assert "r1: agent r1, 2 places, 2 transitions, on remote agent robot1" in text
    assert "here: agent here, 0 places, 1 transitions\n" in text
    assert "go: core.wait {\"seconds\": 0.2} (on robot1)" in text and "finish: core.wait {\"seconds\": 0.1}\n" in text
    assert "remote agents (bridge: mqtt tcp/127.0.0.1:1883):\n    robot1: subnets r1; transitions go, mark" in text
    assert main(["info", str(net), "--config", str(tmp_path / "other.yaml"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["remote"] == {"transport": "mqtt", "connect": "tcp/127.0.0.1:1883",
                              "agents": {"robot1": {"subnets": ["r1"], "transitions": ["go", "mark"]}}}
    assert {sid: sub["remote_agent"] for sid, sub in info["subnets"].items()} == {"r1": "robot1", "here": None}


def test_info_without_a_bridge_marks_nothing_remote(tmp_path, capsys):
    net = write(tmp_path, "mqtt", "tcp/127.0.0.1:1883")
    (tmp_path / "run.yaml").write_text("seed: 1\n")
    assert main(["info", str(net), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["remote"] is None and all(sub["remote_agent"] is None for sub in info["subnets"].values())


def test_info_with_a_bridge_naming_an_unknown_subnet_is_one_line(tmp_path, capsys):
    net = write(tmp_path, "mqtt", "tcp/127.0.0.1:1883")
    (tmp_path / "run.yaml").write_text('seed: 1\nbridge: {transport: mqtt, agents: {r2: robot1}}\n')
    assert main(["info", str(net)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'r2'" in err and "Traceback" not in err
