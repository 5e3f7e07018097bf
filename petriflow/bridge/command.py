"""``petriflow agent`` and ``petriflow router``: the bridge's commands.

``petriflow agent --name NAME [--name NAME ...] --transport zenoh|mqtt --connect
ENDPOINT [--actions MODULE ...] [--world WORLD.yaml]`` serves the registry's actions
(with those of ``--actions`` modules, ``.py`` files or importable names) under each
name until interrupted; ``petriflow router [--listen ENDPOINT]`` runs a Zenoh router
in Python until interrupted.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from typing import Any

from petriflow import limits
from petriflow.errors import PetriflowError

__all__ = ["add_parser", "cmd_agent", "cmd_router"]


def _stop_on_signals(stop: Any) -> None:
    def handler(signum: int, frame: Any) -> None:
        stop()

    signal.signal(signal.SIGTERM, handler)
    signal.signal(signal.SIGINT, handler)


def cmd_router(args: argparse.Namespace) -> int:
    from petriflow.bridge.transport import Endpoint
    from petriflow.bridge.zenoh_transport import serve_router

    users = None
    if args.user is not None:
        password = os.environ.get(args.password_env or "", None)
        if password is None:
            raise PetriflowError(f"--user needs its password in the environment variable {args.password_env!r}")
        users = {args.user: password}
    router = serve_router(Endpoint(args.listen), users=users)
    done = threading.Event()
    _stop_on_signals(done.set)
    print(f"petriflow router: listening on {args.listen}", flush=True)
    try:
        done.wait()
    finally:
        router.close()
    return 0


def cmd_agent(args: argparse.Namespace) -> int:
    from petriflow.bridge.agent import AgentServer
    from petriflow.bridge.spec import DEFAULT_CONNECT
    from petriflow.bridge.transport import AGENT_NAME, Endpoint, open_transport
    from petriflow.runtime.config import RunConfig

    for name in args.name:
        if not AGENT_NAME.match(name):
            raise PetriflowError(f"--name {name!r}: an agent name is letters, digits, '_', '.', '-' (at most 64)")
    if not args.speed > 0:
        raise PetriflowError(f"--speed must be > 0, got {args.speed}")
    if not args.call_timeout > 0:
        raise PetriflowError(f"--call-timeout must be > 0, got {args.call_timeout}")
    if args.actions:
        config = RunConfig(actions=[os.path.abspath(a) if a.endswith(".py") else a for a in args.actions])
        config.import_actions()
    world = None
    if args.world is not None:
        from petriflow.world import load_world

        world = load_world(args.world)
    password = os.environ.get(args.password_env) if args.password_env else None
    endpoint = Endpoint(args.connect or DEFAULT_CONNECT[args.transport], args.user, password)
    transport = open_transport(args.transport, endpoint, "-".join(args.name))
    log_file = open(args.log, "a", encoding="utf-8") if args.log else None
    server = AgentServer(args.name, transport, world=world, speed=args.speed, heartbeat=args.heartbeat,
                         log_file=log_file, call_timeout=args.call_timeout)
    _stop_on_signals(server.stop)
    print(f"petriflow agent: {', '.join(args.name)} serving {len(server.actions)} actions over {args.transport}"
          f" at {endpoint.connect}", flush=True)
    try:
        server.serve()
    finally:
        transport.close()
        if world is not None:
            world.close()
        if log_file is not None:
            log_file.close()
    print(f"petriflow agent: stopped after {server.executed} goals ({server.dropped} messages dropped)",
          file=sys.stderr)
    return 0


def add_parser(sub: Any) -> None:
    """Add ``agent`` and ``router`` to the command line's subcommands."""
    agent = sub.add_parser(
        "agent", help="Serve actions to runs over the network: the robot's side of a bridged run.",
        description="Serve the registry's actions (and those of --actions modules) to runs whose run"
        " configuration puts a subnet on this agent (bridge: in docs/bridge.md), in wall-clock time; with"
        " --world, in a pybullet world of its own (a stand-in for the robot). Runs until interrupted.")
    agent.add_argument("--name", action="append", required=True,
                       help="the agent name served (repeat to serve several)")
    agent.add_argument("--transport", choices=("zenoh", "mqtt"), required=True)
    agent.add_argument("--connect", help="the router or broker (default: zenoh tcp/127.0.0.1:7447, mqtt"
                       " tcp/127.0.0.1:1883)")
    agent.add_argument("--actions", nargs="+", metavar="MODULE", help="modules that register actions"
                       " (.py files or importable names)")
    agent.add_argument("--world", help="a world file: run the actions in a pybullet world of this agent's own")
    agent.add_argument("--speed", type=limits.number_argument, default=1.0,
                       help="agent seconds per wall-clock second (default 1; more for demonstrations)")
    agent.add_argument("--heartbeat", type=limits.number_argument, default=0.5, help="seconds between heartbeats")
    agent.add_argument("--call-timeout", type=limits.number_argument, default=60.0,
                       help="seconds an action waits for the run to answer a call of its services (ctx.read,"
                       " ctx.running); then it fails (default 60)")
    agent.add_argument("--log", help="append one JSON line per goal executed to this file")
    agent.add_argument("--user", help="authenticate to the router or broker as this user")
    agent.add_argument("--password-env", help="the environment variable that holds the password")
    agent.set_defaults(handler=cmd_agent)

    router = sub.add_parser("router", help="Run a Zenoh router (in Python) for bridged runs.",
                            description="Run a Zenoh router until interrupted.")
    router.add_argument("--listen", default="tcp/127.0.0.1:7447", help="endpoint (default tcp/127.0.0.1:7447)")
    router.add_argument("--user", help="accept only clients authenticated as this user")
    router.add_argument("--password-env", help="the environment variable that holds its password")
    router.set_defaults(handler=cmd_router)
