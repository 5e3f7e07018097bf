"""The orchestrator's side of the bridge: goals out, answers in, agents watched.

A :class:`Dispatcher` holds one transport connection for a run. The run's thread
sends goals and cancels and reads their state (:meth:`Dispatcher.goal`); the
transport's thread delivers what agents send, which is decoded, checked against what
this run sent and counted when dropped (:attr:`Dispatcher.dropped`, by
:class:`~petriflow.bridge.protocol.Drop`); a heartbeat thread tells the agents the run
is alive and sends again, with the same id, every goal an agent is not known to hold
(lost in a broker restart: the agent answers from what it remembers of that id, and
never runs it twice).

An agent is *lost* when nothing came from it for ``heartbeat_timeout`` seconds; it is
back when it announces itself again. A cancel not acknowledged within
``cancel_timeout`` seconds gives its goal up (:attr:`Phase.ABANDONED`: what the action
did is unknown) and holds its agent lost while the agent's heartbeats still list that
goal (it may still be doing it). :meth:`Dispatcher.watch` says which agents were lost
or came back since it was last asked, so the run changes its own state only in its
own thread.

**Memory stays flat**: the run says when it is done with a goal (:meth:`Dispatcher.done`,
once its firing ended: the result taken, the ``end`` event recorded), and the goal's
state is dropped. What de-duplication needs is kept: the ids of the last
:data:`KEPT_ENDED` goals each agent ended, each with whether a second answer is
expected (the goal or its cancel was sent again). A message about an id in that record
is dropped (counted as ``replayed`` unless expected); an older one is dropped as
``unknown_goal``. Either way it is never recorded: answers for a goal come within a few
heartbeats of its end (every re-send is paced by heartbeats), so the last thousand
ended ids of an agent cover every duplicate a working agent or broker sends, and only
a replay from far back lands under the other reason.
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Callable

from petriflow.bridge import protocol
from petriflow.bridge.calls import check_call
from petriflow.bridge.protocol import Drop, Refused
from petriflow.bridge.spec import BridgeSpec
from petriflow.bridge.transport import Transport, agent_of, from_agent, open_transport, to_agent

__all__ = ["Dispatcher", "GoalState", "AgentSeen", "Phase"]

log = logging.getLogger("petriflow.bridge")
#: Drops logged per reason (the rest are only counted).
LOGGED_DROPS = 5
#: Replies kept per goal to answer a call sent again (the latest ones).
KEPT_REPLIES = 64
#: Ended goal ids kept per agent after the run is done with them (for de-duplication).
KEPT_ENDED = 1024
#: Feedback messages of one goal kept until the run records them (the latest ones).
KEPT_FEEDBACK = 64


class Phase:
    """Where a goal is (plain strings: they are compared, logged and recorded)."""

    SENT = "sent"
    ACCEPTED = "accepted"
    REJECTED = "rejected"
    OK = "ok"
    FAILED = "failed"
    CANCELLED = "cancelled"
    #: The run gave the goal up: its cancel was not acknowledged within ``cancel_timeout``.
    ABANDONED = "abandoned"
    ENDED = (REJECTED, OK, FAILED, CANCELLED, ABANDONED)


@dataclass
class GoalState:
    """One goal this run sent, and what came back.

    Attributes:
        goal: the goal.
        phase: a :class:`Phase`.
        sent: wall-clock time (``time.perf_counter``) it was first sent.
        answered: wall-clock time of its result (``None`` before).
        resent: how many times it was sent again.
        data: the result's output token data.
        reason: why it failed or was rejected.
        cancel_sent: wall-clock time a cancel was sent last (``None``: none).
        cancel_asked: wall-clock time the first cancel was sent (its deadline counts
            from it: ``cancel_timeout``).
        cancels_resent: how many times the cancel was sent again (not acknowledged yet:
            an agent computing answers each when its action's call returns).
        feedback: the last feedback's data.
        feedbacks: the feedback data received and not yet taken by the run
            (:meth:`Dispatcher.take_feedback`), oldest first, the latest
            :data:`KEPT_FEEDBACK`; ``skipped``: how many older ones were left out.
    """

    goal: protocol.Goal
    phase: str = Phase.SENT
    sent: float = 0.0
    last_sent: float = 0.0
    answered: float | None = None
    resent: int = 0
    data: Any = None
    reason: str = ""
    cancel_sent: float | None = None
    cancel_asked: float | None = None
    cancels_resent: int = 0
    feedback: Any = None
    feedbacks: list[Any] = field(default_factory=list)
    skipped: int = 0
    #: Calls of the goal's action waiting for the kernel to answer them (:mod:`~.calls`).
    calls: list[protocol.Call] = field(default_factory=list)
    #: The replies sent, by call number (a call sent again is answered the same).
    replies: dict[int, protocol.Reply] = field(default_factory=dict)
    #: How many of the action's calls the run answered (recorded with the goal's end).
    answered_calls: int = 0
    #: On resume, the simulated time the journal shows it ended at (its ending is taken
    #: then, as journaled: :mod:`petriflow.bridge.resume`); ``None``: a live goal.
    at: float | None = None

    @property
    def ended(self) -> bool:
        """Whether the goal ended (a result, a rejection or a cancel's acknowledgement)."""
        return self.phase in Phase.ENDED

    @property
    def round_trip(self) -> float | None:
        """Seconds from the goal sent to its end received."""
        return None if self.answered is None else self.answered - self.sent


@dataclass
class AgentSeen:
    """What the run knows of one agent."""

    name: str
    actions: dict[str, dict[str, Any]] = field(default_factory=dict)
    instance: str = ""
    last: float = 0.0
    running: set[str] = field(default_factory=set)
    announced: bool = False


class Dispatcher:
    """The run's connection to its remote agents (see the module).

    Args:
        spec: the configuration's ``bridge:`` section.
        transport: an open transport (default: opened from ``spec``).
        run: this run's name in goal ids (default: a new random one).
        now: the wall clock (seconds).
    """

    def __init__(self, spec: BridgeSpec, transport: Transport | None = None, *, run: str | None = None,
                 now: Callable[[], float] = time.perf_counter) -> None:
        self.spec = spec
        self.run = run or uuid.uuid4().hex[:12]
        self.now = now
        self.names = set(spec.agents.values())
        self.agents: dict[str, AgentSeen] = {name: AgentSeen(name) for name in self.names}
        #: The goals the run is not done with (:meth:`done`), by id.
        self.goals: dict[str, GoalState] = {}
        #: Per agent, the ids of the goals the run was done with (the latest
        #: :data:`KEPT_ENDED`), each with whether a second answer is expected and its phase.
        self.ended: dict[str, dict[str, tuple[bool, str]]] = {name: {} for name in self.names}
        self.dropped: Counter[str] = Counter()
        self._lock = threading.Lock()
        self._announced = threading.Condition(self._lock)
        self._ended = threading.Condition(self._lock)
        self._lost: set[str] = set()
        self._why: dict[str, str] = {}  # lost agent -> why
        self._held: dict[str, set[str]] = {}  # agent -> the goals given up that it may still be doing
        self._feedback: set[str] = set()  # goals with feedback the run has not taken
        self._taken_late: list[tuple[protocol.Goal, list[Any], int]] = []  # ... of goals done meanwhile
        self._stop = threading.Event()
        self.transport = transport or open_transport(spec.transport, spec.endpoint(), "orchestrator")
        self.transport.subscribe(from_agent("*"), self.receive)
        self._beat = threading.Thread(target=self._heartbeats, name="petriflow-bridge-heartbeat", daemon=True)
        self._beat.start()

    # what the transport's thread calls ------------------------------------------------
    def drop(self, reason: Drop, detail: str) -> None:
        """Count (and log the first few of) a message dropped for ``reason``."""
        with self._lock:
            self.dropped[reason.value] += 1
            count = self.dropped[reason.value]
        if count <= LOGGED_DROPS:
            log.warning("bridge: dropped a message (%s): %s", reason.value, detail[:200])

    def receive(self, topic: str, payload: bytes) -> None:
        """One message from an agent (the transport's handler): checked, then applied."""
        sender = agent_of(topic)
        if sender not in self.names:
            self.drop(Drop.UNKNOWN_AGENT, f"from {sender[:64]!r}, which the run's bridge does not list")
            return
        try:
            message = protocol.decode(payload)
        except Refused as exc:
            self.drop(exc.drop, f"from {sender!r}: {exc}")
            return
        if getattr(message, "agent", sender) != sender:
            self.drop(Drop.WRONG_AGENT, f"{message.kind.value} on {sender!r}'s topic names agent"
                                        f" {getattr(message, 'agent', '')!r}")
            return
        if isinstance(message, (protocol.Goal, protocol.Cancel, protocol.Reply)):
            self.drop(Drop.MALFORMED, f"an agent sent a {message.kind.value}")
            return
        now = self.now()
        with self._lock:
            seen = self.agents[sender]
            seen.last = now
            if isinstance(message, protocol.Announce):
                if seen.instance and message.instance != seen.instance:
                    self._restarted(seen, now)
                seen.actions, seen.instance, seen.announced = message.actions, message.instance, True
                self._announced.notify_all()
                return
            if isinstance(message, protocol.Heartbeat):
                seen.running = set(message.running)
                return
            state = self.goals.get(message.id)
            ended = self.ended[sender].get(message.id)
        if state is None and ended is not None:
            self._after_end(sender, message, *ended)
            return
        if state is None:
            self.drop(Drop.UNKNOWN_GOAL, f"{message.kind.value} from {sender!r} for goal {message.id[:80]!r},"
                                         " which this run never sent")
            return
        if state.goal.agent != sender:
            self.drop(Drop.WRONG_AGENT, f"{message.kind.value} from {sender!r} for a goal sent to"
                                        f" {state.goal.agent!r}")
            return
        if isinstance(message, protocol.Call):
            self._called(state, message)
            return
        self._apply(state, message, now)

    def _after_end(self, sender: str, message: protocol.BridgeMessage, expected: bool, phase: str) -> None:
        """A message about a goal the run was done with (forgotten but for its id): a
        call is refused, an expected second answer dropped, anything else dropped and
        counted as a replay; nothing is recorded."""
        if isinstance(message, protocol.Call):
            why = check_call(message)
            if why:
                self.drop(Drop.UNKNOWN_CALL, f"from {sender!r} for goal {message.id[:80]!r}: {why}")
            else:
                self.transport.publish(to_agent(sender), protocol.encode(protocol.Reply(
                    message.id, sender, message.call, None,
                    f"the goal ended ({phase}): the run answers no more calls for it")))
            return
        if not (expected or isinstance(message, (protocol.Accepted, protocol.Feedback))):
            self.drop(Drop.REPLAYED, f"{message.kind.value} for goal {message.id[:80]!r}, which had ended")

    def _called(self, state: GoalState, call: protocol.Call) -> None:
        """A call of a goal's action: kept for the kernel to answer (:meth:`take_calls`),
        answered again if it was, refused if the goal ended, dropped if not served."""
        why = check_call(call)
        if why:
            self.drop(Drop.UNKNOWN_CALL, f"from {call.agent!r} for goal {call.id[:80]!r}: {why}")
            return
        with self._lock:
            reply = state.replies.get(call.call)
            if reply is None and state.ended:
                reply = protocol.Reply(call.id, call.agent, call.call, None,
                                       f"the goal ended ({state.phase}): the run answers no more calls for it")
            elif reply is None:
                if all(c.call != call.call for c in state.calls):
                    state.calls.append(call)
                return
        self.transport.publish(to_agent(call.agent), protocol.encode(reply))

    def take_calls(self, goal_id: str) -> list[protocol.Call]:
        """The calls of the goal's action not yet answered, oldest first (the kernel's
        thread answers them with :meth:`reply`)."""
        with self._lock:
            state = self.goals.get(goal_id)
            if state is None or not state.calls:
                return []
            calls, state.calls = state.calls, []
            return calls

    def reply(self, reply: protocol.Reply) -> None:
        """Send ``reply`` (and keep it: a call sent again gets it again)."""
        with self._lock:
            state = self.goals.get(reply.id)
            if state is not None:
                if reply.call not in state.replies:
                    state.answered_calls += 1
                state.replies[reply.call] = reply
                if len(state.replies) > KEPT_REPLIES:  # a call that old is not sent again
                    del state.replies[min(state.replies)]
        self.transport.publish(to_agent(reply.agent), protocol.encode(reply))

    def _restarted(self, seen: AgentSeen, now: float) -> None:
        """``seen`` announced itself as a new process: the goals its old one held died
        with it (they fail; sending them again would run them a second time). Holds
        the lock."""
        for state in self.goals.values():
            if state.goal.agent == seen.name and not state.ended:
                state.phase, state.answered = Phase.FAILED, now
                state.reason = "the agent restarted while the goal ran (its outcome is unknown)"
        self._held.pop(seen.name, None)  # what the old process held died with it
        self._ended.notify_all()

    def _apply(self, state: GoalState, message: protocol.BridgeMessage, now: float) -> None:
        with self._lock:
            if state.ended:
                replayed = True
            else:
                replayed = False
                if isinstance(message, protocol.Accepted):
                    state.phase = Phase.ACCEPTED
                elif isinstance(message, protocol.Feedback):
                    state.feedback = message.data
                    state.feedbacks.append(message.data)
                    if len(state.feedbacks) > KEPT_FEEDBACK:
                        del state.feedbacks[0]
                        state.skipped += 1
                    self._feedback.add(state.goal.id)
                elif isinstance(message, protocol.Rejected):
                    state.phase, state.reason, state.answered = Phase.REJECTED, message.reason, now
                elif isinstance(message, protocol.Result):
                    state.phase = Phase.OK if message.outcome == "ok" else Phase.FAILED
                    state.data, state.reason, state.answered = message.data, message.reason, now
                elif isinstance(message, protocol.Cancelled):
                    state.phase, state.answered = Phase.CANCELLED, now
                if state.ended:
                    self._ended.notify_all()
        # an answer to a goal or a cancel sent again is expected twice; otherwise an ended goal's
        # answer is a replay
        expected = (state.resent or state.cancels_resent) and state.phase != Phase.ABANDONED or \
            isinstance(message, (protocol.Accepted, protocol.Feedback))
        if replayed and not expected:
            self.drop(Drop.REPLAYED, f"{message.kind.value} for goal {state.goal.id!r}, which had ended")

    # what the run's thread calls --------------------------------------------------------
    def wait_for(self, seconds: float) -> list[str]:
        """Wait up to ``seconds`` for every agent to announce itself; the names of those
        that did not, sorted."""
        deadline = self.now() + seconds
        with self._lock:
            while True:
                missing = sorted(name for name, seen in self.agents.items() if not seen.announced)
                left = deadline - self.now()
                if not missing or left <= 0:
                    return missing
                self._announced.wait(min(left, 0.1))

    def announced(self, agent: str) -> dict[str, dict[str, Any]] | None:
        """``{action: {parameter: declaration}}`` ``agent`` announced (``None``: it did not)."""
        with self._lock:
            seen = self.agents.get(agent)
            return dict(seen.actions) if seen is not None and seen.announced else None

    def send(self, goal: protocol.Goal) -> GoalState:
        """Send ``goal`` (again, if a goal of its id was sent: its state is kept)."""
        now = self.now()
        with self._lock:
            state = self.goals.get(goal.id)
            if state is None:
                state = self.goals[goal.id] = GoalState(goal, sent=now)
            state.last_sent = now
        self.transport.publish(to_agent(goal.agent), protocol.encode(goal))
        return state

    def goal(self, goal_id: str) -> GoalState | None:
        """The state of the goal ``goal_id``."""
        with self._lock:
            return self.goals.get(goal_id)

    def wait_goal(self, goal_id: str, seconds: float) -> GoalState | None:
        """The goal's state once it ended, or after ``seconds`` (``None``: never sent)."""
        deadline = self.now() + seconds
        with self._lock:
            while True:
                state = self.goals.get(goal_id)
                left = deadline - self.now()
                if state is None or state.ended or left <= 0:
                    return state
                self._ended.wait(left)

    def cancel(self, goal_id: str) -> None:
        """Ask the agent to stop the goal (again after a heartbeat until acknowledged)."""
        with self._lock:
            state = self.goals.get(goal_id)
            if state is None or state.ended:
                return
            state.cancel_sent = self.now()
            if state.cancel_asked is None:
                state.cancel_asked = state.cancel_sent
            goal = state.goal
        self.transport.publish(to_agent(goal.agent), protocol.encode(protocol.Cancel(goal.id, goal.agent)))

    def forget(self, goal_id: str) -> None:
        """The run gave this goal up (its agent lost): its calls waiting for an answer
        are refused, and the run is done with it (:meth:`done`); any answer that comes
        later is dropped and counted."""
        with self._lock:
            state = self.goals.get(goal_id)
            if state is not None and not state.ended:
                state.phase = Phase.CANCELLED
                state.resent = state.cancels_resent = 0  # nothing more is expected from it
        self.refuse_calls(goal_id, "the run gave up the goal (cancelled, or its agent lost)")
        self.done(goal_id)

    def done(self, goal_id: str) -> None:
        """The run is done with this goal (its firing ended): its state is dropped, its
        id kept in its agent's record of ended goals (the last :data:`KEPT_ENDED`) for
        de-duplication. A goal not ended yet is left as it is."""
        with self._lock:
            state = self.goals.get(goal_id)
            if state is None or not state.ended:
                return
            del self.goals[goal_id]
            if goal_id in self._feedback:  # came with its end: still to be recorded
                self._feedback.discard(goal_id)
                self._taken_late.append((state.goal, state.feedbacks, state.skipped))
            record = self.ended.setdefault(state.goal.agent, {})
            record[goal_id] = (bool(state.resent or state.cancels_resent) and state.phase != Phase.ABANDONED,
                               state.phase)
            if len(record) > KEPT_ENDED:
                del record[next(iter(record))]

    def take_feedback(self) -> list[tuple[protocol.Goal, list[Any], int]]:
        """``(goal, [feedback data, ...], skipped)`` of each goal with feedback the run
        has not taken yet, in goal id order (the run's thread records them)."""
        with self._lock:
            if not (self._feedback or self._taken_late):
                return []
            out, self._taken_late = self._taken_late, []
            for goal_id in sorted(self._feedback):
                state = self.goals.get(goal_id)
                if state is not None and state.feedbacks:
                    out.append((state.goal, state.feedbacks, state.skipped))
                    state.feedbacks, state.skipped = [], 0
            self._feedback.clear()
            return out

    def refuse_calls(self, goal_id: str, why: str) -> None:
        """Refuse the goal's calls waiting for an answer, with ``why``."""
        for call in self.take_calls(goal_id):
            self.reply(protocol.Reply(call.id, call.agent, call.call, None, why))

    def is_lost(self, agent: str) -> bool:
        """Whether ``agent`` was lost (as :meth:`watch` last found)."""
        return agent in self._lost

    def watch(self) -> tuple[list[str], list[str]]:
        """``(lost, back)``: the agents lost and those back since the last call. An agent
        is lost when silent for ``heartbeat_timeout``, or when a cancel sent to it went
        unacknowledged for ``cancel_timeout`` (the goal is given up: :attr:`Phase.ABANDONED`);
        it is back when it announced itself since and its heartbeats no longer list a
        goal given up. :meth:`why_lost` says why."""
        now, timeout = self.now(), self.spec.heartbeat_timeout
        lost, back = [], []
        with self._lock:
            self._give_up(now)
            for name, seen in sorted(self.agents.items()):
                held = self._held.get(name)
                if held is not None:
                    held &= seen.running  # goals given up that it still does
                    if not held:
                        del self._held[name]
                silent = not seen.announced or now - seen.last > timeout
                if (silent or held) and name not in self._lost and (seen.announced or held):
                    self._lost.add(name)
                    seen.announced = False  # back only when it announces itself again
                    lost.append(name)
                    if not held:
                        self._why[name] = f"no message for {now - seen.last:.1f} s (heartbeat_timeout {timeout:g} s)"
                elif not silent and not held and name in self._lost:
                    self._lost.discard(name)
                    self._why.pop(name, None)
                    back.append(name)
        return lost, back

    def _give_up(self, now: float) -> None:
        """Give up each goal whose cancel went unacknowledged for ``cancel_timeout``; its
        agent is held lost while it lists the goal. Holds the lock."""
        limit = self.spec.cancel_timeout
        for state in self.goals.values():
            if state.cancel_asked is None or state.ended or now - state.cancel_asked <= limit:
                continue
            agent = state.goal.agent
            state.phase, state.answered = Phase.ABANDONED, now
            state.reason = (f"the cancel of goal {state.goal.id} was not acknowledged within {limit:g} s"
                            " (what the action did is unknown)")
            self._held.setdefault(agent, set()).add(state.goal.id)
            self.agents[agent].running.add(state.goal.id)  # held until a heartbeat says otherwise
            if agent not in self._lost:
                self._why[agent] = f"it did not acknowledge the cancel of {state.goal.transition or state.goal.id!r}" \
                                   f" within {limit:g} s (cancel_timeout)"
            self._ended.notify_all()

    def why_lost(self, agent: str) -> str:
        """Why ``agent`` is lost (as :meth:`watch` found)."""
        with self._lock:
            return self._why.get(agent) or "no message (heartbeat_timeout)"

    def mark_lost(self, agent: str) -> None:
        """Hold ``agent`` lost (the run had lost it before a resume) until it announces itself."""
        with self._lock:
            self._lost.add(agent)
            self._why[agent] = "lost before the run was resumed"
            self.agents[agent].announced = False

    def silence(self, agent: str) -> float:
        """Seconds since ``agent`` was last heard from."""
        with self._lock:
            return self.now() - self.agents[agent].last

    # the heartbeat thread -----------------------------------------------------------------
    def _heartbeats(self) -> None:
        beat = protocol.encode(protocol.Heartbeat(""))
        period = self.spec.heartbeat
        while not self._stop.wait(period):
            try:
                for name in sorted(self.names):
                    self.transport.publish(to_agent(name), beat)
                self.send_again()
            except Exception as exc:  # a transport error must not end the heartbeats
                log.warning("bridge: heartbeat failed: %s", exc)

    def send_again(self) -> None:
        """Send again each goal its agent does not hold (not in its last heartbeat) and
        each cancel not acknowledged, once a heartbeat has passed since the last send."""
        now, period = self.now(), self.spec.heartbeat
        goals, cancels = [], []
        with self._lock:
            for state in self.goals.values():
                if state.ended:
                    continue
                seen = self.agents[state.goal.agent]
                if state.cancel_sent is not None:
                    if now - state.cancel_sent > period:
                        state.cancel_sent = now
                        state.cancels_resent += 1
                        cancels.append(state.goal)
                elif state.goal.id not in seen.running and now - state.last_sent > 2 * period and \
                        seen.last > state.last_sent:
                    state.last_sent = now
                    state.resent += 1
                    goals.append(state.goal)
        for goal in goals:
            self.transport.publish(to_agent(goal.agent), protocol.encode(goal))
        for goal in cancels:
            self.transport.publish(to_agent(goal.agent), protocol.encode(protocol.Cancel(goal.id, goal.agent)))

    def close(self) -> None:
        """Stop the heartbeats and disconnect."""
        self._stop.set()
        self._beat.join(timeout=5)
        self.transport.close()

    def __enter__(self) -> "Dispatcher":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

