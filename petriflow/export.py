"""Drawing nets with Graphviz, and exporting them in every format petriflow writes.

:func:`to_dot` turns a net (and a marking) into Graphviz DOT text: places are circles
holding their tokens, transitions are boxes naming the action they run, agent subnets
are labelled clusters. Every node shows its id beside its label (``T5 · start
cooperative task``), so the picture matches the ids that ``check``, ``replay`` and
error messages name. WF operators carry WoPeD-style markers (the parts of an XOR side
are grouped in a dashed frame); running transitions (``replay --draw``) are drawn in
their own colour with the tokens they hold. :func:`render` runs the ``dot`` program to
make SVG or PNG, and :func:`export_net` is what ``petriflow export`` calls for any of
``pnml``, ``yaml``, ``dot``, ``svg`` and ``png``; it lays a picture out left to right,
or top to bottom when that would be too wide to read (``rankdir="auto"``).

Only ``dot`` itself is needed for pictures (no Python Graphviz binding); DOT text can
be made without it.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net("demo")
    >>> _ = net.add_place("ready", tokens=1)
    >>> _ = net.add_place("done")
    >>> _ = net.add_transition("go", action="robot.move")
    >>> _ = net.add_arc("ready", "go"), net.add_arc("go", "done", weight=2)
    >>> source = to_dot(net)
    >>> source.startswith('digraph "demo" {'), "rankdir=LR" in source
    (True, True)
    >>> "<B>go</B>" in source, "ready" in source
    (True, True)
    >>> print(next(line.strip() for line in source.splitlines() if "->" in line))
    "ready" -> "go";
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path
from typing import Mapping, Sequence

from petriflow.dot import CLUSTER_COLOURS, FONT, arc_look, attributes, html_text, quote, tokens_text
from petriflow.errors import DependencyNotInstalled, PetriflowError, UnknownElementError
from petriflow.net import Net

__all__ = [
    "to_dot", "render", "export_net", "format_of", "EXPORT_FORMATS", "PICTURE_FORMATS", "DOT_EXECUTABLE",
    "HIGHLIGHT_COLOUR", "RUNNING_COLOUR", "RANK_DIRECTIONS", "FULL_SIZE",
]

#: Every format :func:`export_net` writes.
EXPORT_FORMATS = ("pnml", "yaml", "dot", "svg", "png")
#: The formats :func:`render` makes with Graphviz.
PICTURE_FORMATS = ("svg", "png")
#: Name (or path) of the Graphviz layout program; looked up on ``PATH``.
DOT_EXECUTABLE = "dot"
#: Seconds ``dot`` may run before :func:`render` gives up.
DOT_TIMEOUT_S = 60.0
#: Resolution of PNG pictures (Graphviz's default of 96 is blurry for small labels).
PNG_DPI = 150
#: The largest a picture of every node of a big net may be, ``(width, height)`` in inches
#: (6000 pixels a side in PNG): a net of more than :data:`~petriflow.fold.FOLD_ABOVE`
#: nodes drawn in full is scaled down to fit, and :func:`export_net` says so.
FULL_SIZE = (40.0, 40.0)

_MISSING_DOT = "Graphviz 'dot' not found: run scripts/setup.sh or apt-get install graphviz"

# Colours and sizes. Inches for sizes, points for fonts, as Graphviz counts them.
#: Colour of highlighted nodes and arcs (see :func:`to_dot`).
HIGHLIGHT_COLOUR = "#d62728"
_HIGHLIGHT_FILL = "#fde0dd"
#: Colour of transitions whose actions are running (see :func:`to_dot`).
RUNNING_COLOUR = "#1f6fb4"
_RUNNING_FILL = "#d7e8f7"
#: Layout directions: left to right, top to bottom, or chosen from the net's shape.
RANK_DIRECTIONS = ("LR", "TB", "auto")
#: With ``rankdir="auto"``, a left-to-right layout wider than this many times its
#: height is drawn top to bottom instead.
AUTO_RATIO = 2.2
_TRANSITION_FILL = "#dfe6ee"
_PLACE_SIZE = 0.42
_NAME_ROW = 14  # points: height of the name under a place
_SEPARATOR = " \u00b7 "  # between a node's id and its label



# DOT text ------------------------------------------------------------------------------


def _place_lines(net: Net, place: str, count: int, highlighted: bool, indent: str) -> str:
    """A place: a circle, with its name in the same label under it.

    ``fixedsize=shape`` keeps the circle small while the label (a three-row table: a
    spacer as tall as the name row, the circle's inside, the name) stays centred on
    it, so the name always sits right under its own circle and never on anything else.
    """
    spec = net.places[place]
    colour = HIGHLIGHT_COLOUR if highlighted else "black"
    side = round(_PLACE_SIZE * 72)
    name = html_text(_name(spec.id, spec.label))
    label = (
        '<<TABLE BORDER="0" CELLBORDER="0" CELLSPACING="0" CELLPADDING="0">'
        f'<TR><TD HEIGHT="{_NAME_ROW}"> </TD></TR>'
        f'<TR><TD HEIGHT="{side}" WIDTH="{side}" FIXEDSIZE="TRUE">{tokens_text(count)}</TD></TR>'
        f'<TR><TD HEIGHT="{_NAME_ROW}" VALIGN="BOTTOM">{name}</TD></TR>'
        "</TABLE>>"
    )
    attrs = {"label": label, "color": f'"{colour}"', "fontcolor": f'"{colour}"'}
    if highlighted:
        attrs["penwidth"] = "2.5"
    return f"{indent}{quote(place)} {attributes(attrs)};"


def _name(node_id: str, label: str | None) -> str:
    """What a node is called in pictures: its id, and its label when it has another.

    Examples:
        >>> _name("T5", "start cooperative task"), _name("go", None), _name("go", "go")
        ('T5 · start cooperative task', 'go', 'go')
    """
    return node_id if not label or label == node_id else f"{node_id}{_SEPARATOR}{label}"


def _operator_marker(net: Net, transition: str) -> str | None:
    """The WoPeD-style marker of a transition that is (part of) a WF operator.

    Examples:
        >>> from petriflow.workflow import add_operator
        >>> net = Net()
        >>> for p in ("a", "b", "c"): _ = net.add_place(p)
        >>> add_operator(net, "pick", inputs={"a": 1}, outputs={"b": 1, "c": 1}, split="xor")
        ['pick_op_1', 'pick_op_2']
        >>> _operator_marker(net, "pick_op_2")
        'XOR-split ▷ pick, branch 2 of 2'
    """
    operator = net.transitions[transition].operator
    if operator is None:
        return None
    sides = []
    if operator.join:
        sides.append(f"\u25c1 {operator.join.upper()}-join")
    if operator.split:
        sides.append(f"{operator.split.upper()}-split \u25b7")
    text = " \u00b7 ".join(sides) or "operator"
    parts = [t.id for t in net.transitions.values() if t.operator is not None and t.operator.group == operator.group]
    if len(parts) > 1:
        return f"{text} {operator.group}, branch {parts.index(transition) + 1} of {len(parts)}"
    return text if operator.group == transition else f"{text} {operator.group}"


def _transition_lines(net: Net, transition: str, highlighted: bool, indent: str,
                      holding: Mapping[str, int] | None = None) -> str:
    spec = net.transitions[transition]
    colour = HIGHLIGHT_COLOUR if highlighted else (RUNNING_COLOUR if holding is not None else "black")
    if spec.silent:
        attrs = {
            "label": '""', "width": "0.1", "height": "0.45", "fixedsize": "true",
            "style": "filled", "fillcolor": f'"{colour}"', "color": f'"{colour}"',
            "tooltip": quote(_name(spec.id, spec.label)), "xlabel": quote(spec.id),
        }
        return f"{indent}{quote(transition)} {attributes(attrs)};"
    lines = [f"<B>{html_text(_name(spec.id, spec.label))}</B>"]
    marker = _operator_marker(net, transition)
    if marker:
        lines.append(f'<FONT POINT-SIZE="8" COLOR="#7a4f00">{html_text(marker)}</FONT>')
    if spec.action:
        lines.append(f'<FONT POINT-SIZE="8" COLOR="#404040">{html_text(spec.action)}</FONT>')
    if spec.guard:
        lines.append(f'<FONT POINT-SIZE="8" COLOR="#404040">[{html_text(spec.guard)}]</FONT>')
    if holding is not None:
        held = ", ".join(p if n == 1 else f"{p}\u00d7{n}" for p, n in holding.items()) or "no token"
        lines.append(f'<FONT POINT-SIZE="8" COLOR="{RUNNING_COLOUR}">running, holds {html_text(held)}</FONT>')
    fill = _HIGHLIGHT_FILL if highlighted else (_RUNNING_FILL if holding is not None else _TRANSITION_FILL)
    attrs = {
        "label": "<" + "<BR/>".join(lines) + ">",
        "fillcolor": f'"{fill}"',
        "color": f'"{colour}"',
        "fontcolor": f'"{colour}"',
    }
    if highlighted or holding is not None:
        attrs["penwidth"] = "2.5"
    return f"{indent}{quote(transition)} {attributes(attrs)};"


def _highlight_sets(net: Net, highlight: Sequence[str] | None) -> tuple[set[str], set[tuple[str, str]]]:
    """The highlighted nodes, and the arcs to draw bold.

    An arc is bold when both its ends are highlighted, or when it joins two transitions
    that follow each other in ``highlight`` through a place (a firing sequence given as
    transition ids only still shows as a connected path).
    """
    if highlight is None:
        return set(), set()
    if isinstance(highlight, str):
        highlight = [highlight]
    nodes = list(highlight)
    for node in nodes:
        if node not in net.places and node not in net.transitions:
            raise UnknownElementError("node", node, list(net.places) + list(net.transitions))
    chosen = set(nodes)
    arcs = {(a.source, a.target) for a in net.arcs if a.source in chosen and a.target in chosen}
    for first, second in zip(nodes, nodes[1:]):
        if first in net.transitions and second in net.transitions:
            for place in set(net.postset(first)) & set(net.preset(second)):
                arcs.add((first, place))
                arcs.add((place, second))
    return chosen, arcs


def to_dot(
    net: Net,
    marking: Mapping[str, int] | None = None,
    *,
    highlight: Sequence[str] | None = None,
    title: str | None = None,
    caption: str | None = None,
    running: Mapping[str, Mapping[str, int]] | None = None,
    rankdir: str = "LR",
) -> str:
    """Graphviz DOT source drawing ``net`` in ``marking``.

    Places are circles with their tokens inside (dots for 1 to 4, the number from 5)
    and their label (or id) under them; transitions are boxes with their label (or id)
    in bold and the bound action below it; silent transitions are thin black bars.
    Arcs of weight above 1 carry the weight beside them; output arcs reserved for a
    failed, timed-out or cancelled action are dashed, coloured and named by the outcome
    (:func:`arc_look`). Each agent subnet is a labelled cluster
    naming its agent. The layout runs left to right.

    Args:
        net: the net to draw.
        marking: tokens to draw; defaults to the net's initial marking.
        highlight: ids of places and/or transitions to draw in a highlight colour, such
            as a firing sequence that leads to a problem. Arcs whose two ends are
            highlighted are drawn bold in that colour, and so are the arcs through a
            place joining two transitions that follow each other in ``highlight``.
            A single string is taken as one id.
        title: text above the picture; defaults to the net's label or id; ``""`` for
            none.
        caption: a line under the title saying what the picture shows (e.g. what the
            highlighted path is).
        running: ``{transition: {place: tokens}}`` of the transitions whose actions
            are running, with the tokens they took and hold: drawn in their own colour.
        rankdir: ``"LR"`` (left to right) or ``"TB"`` (top to bottom).

    Returns:
        The DOT text (Graphviz reads it with ``dot -Tsvg`` and the like).

    Raises:
        UnknownElementError: ``marking`` or ``highlight`` names a node the net lacks.

    Examples:
        >>> from petriflow.net import Net
        >>> net = Net("n")
        >>> _ = net.add_subnet("cam", label="Camera", agent="robot_1")
        >>> _ = net.add_place("p", tokens=7, subnet="cam")
        >>> "<B>7</B>" in to_dot(net), 'subgraph "cluster_cam"' in to_dot(net)
        (True, True)
    """
    marking = net.initial_marking if marking is None else net.check_marking(marking)
    chosen, bold_arcs = _highlight_sets(net, highlight)
    running = dict(running or {})
    for transition in running:
        net.transition(transition)
    if rankdir not in ("LR", "TB"):
        raise PetriflowError(f"rankdir must be LR or TB, got {rankdir!r}")
    title = (net.label or net.id) if title is None else title

    out = [f"digraph {quote(net.id)} {{"]
    graph = {
        "rankdir": rankdir, "nodesep": "0.3", "ranksep": "0.45", "newrank": "true",
        "fontname": f'"{FONT}"', "fontsize": "12", "pad": "0.25", "outputorder": "edgesfirst",
    }
    heading = [f"<B>{html_text(title)}</B>"] if title else []
    if caption:
        heading.append(f'<FONT POINT-SIZE="11">{html_text(caption)}</FONT>')
    if heading:
        graph.update({"label": "<" + "<BR/>".join(heading) + ">", "labelloc": "t", "fontsize": "14"})
    out.append(f"  graph {attributes(graph)};")
    out.append(
        f'  node [fontname="{FONT}", fontsize=10, shape=circle, fixedsize=shape,'
        f" width={_PLACE_SIZE}, height={_PLACE_SIZE}, penwidth=1.3];"
    )
    out.append(f'  edge [fontname="{FONT}", fontsize=10, arrowsize=0.7, penwidth=1.1];')

    def node_lines(places: list[str], transitions: list[str], indent: str) -> list[str]:
        lines = [_place_lines(net, p, marking[p], p in chosen, indent) for p in places]
        if transitions:
            lines.append(
                f"{indent}node [shape=box, fixedsize=false, style=\"filled,rounded\","
                f" width=0.3, height=0.35, margin=\"0.08,0.03\", penwidth=1.2];"
            )
            groups: dict[str, list[str]] = {}
            for t in transitions:
                operator = net.transitions[t].operator
                if operator is not None and (operator.split == "xor" or operator.join == "xor"):
                    groups.setdefault(operator.group, []).append(t)
            framed = {t for parts in groups.values() if len(parts) > 1 for t in parts}
            lines += [_transition_lines(net, t, t in chosen, indent, running.get(t))
                      for t in transitions if t not in framed]
            for group, parts in groups.items():
                if len(parts) < 2:
                    continue
                lines.append(f"{indent}subgraph {quote('cluster_operator_' + group)} {{")
                lines.append(f'{indent}  graph [label=<<FONT POINT-SIZE="9" COLOR="#7a4f00">operator'
                             f' {html_text(group)}</FONT>>, labeljust=l, style="dashed,rounded",'
                             f' color="#b07d1a", penwidth=1.0, margin=6];')
                lines += [_transition_lines(net, t, t in chosen, indent + "  ", running.get(t)) for t in parts]
                lines.append(f"{indent}}}")
        return lines

    for number, subnet in enumerate(net.subnets.values()):
        fill, border = CLUSTER_COLOURS[number % len(CLUSTER_COLOURS)]
        caption = (
            f'<B>{html_text(subnet.label or subnet.id)}</B><BR ALIGN="LEFT"/>'
            f'<FONT POINT-SIZE="9">agent: {html_text(subnet.agent or subnet.id)}</FONT><BR ALIGN="LEFT"/>'
        )
        out.append(f"  subgraph {quote('cluster_' + subnet.id)} {{")
        out.append(
            f'    graph [label=<{caption}>, labeljust=l, labelloc=t, fontsize=11,'
            f' style="rounded,filled", fillcolor="{fill}", color="{border}", penwidth=1.2,'
            f" margin=10];"
        )
        places, transitions = net.nodes_of(subnet.id)
        out += node_lines(places, transitions, "    ")
        out.append("  }")

    loose_places = [p.id for p in net.places.values() if p.subnet is None]
    loose_transitions = [t.id for t in net.transitions.values() if t.subnet is None]
    out += node_lines(loose_places, loose_transitions, "  ")

    for arc in net.arcs:
        attrs = arc_look(arc.outcome, arc.weight)
        if (arc.source, arc.target) in bold_arcs:
            colour = f'"{HIGHLIGHT_COLOUR}"'
            attrs.update({"color": colour, "fontcolor": colour, "penwidth": "2.8"})
        line = f"  {quote(arc.source)} -> {quote(arc.target)}"
        out.append(f"{line} {attributes(attrs)};" if attrs else f"{line};")
    out.append("}")
    return "\n".join(out) + "\n"


# Pictures ------------------------------------------------------------------------------


def _check_directory(path: Path) -> None:
    parent = path.parent
    if not parent.is_dir():
        raise PetriflowError(f"{path}: output directory {str(parent)!r} does not exist")


def _write(path: Path, data: bytes) -> None:
    from petriflow.io.files import write_atomic

    try:
        write_atomic(path, data)
    except OSError as exc:
        raise PetriflowError(f"{path}: cannot write: {getattr(exc, 'strerror', None) or exc}") from None


def _layout_size(dot_source: str) -> tuple[float, float] | None:
    """Width and height (inches) of the layout ``dot`` makes of ``dot_source``, or
    ``None`` when ``dot`` is missing or fails (the caller then keeps its choice)."""
    executable = shutil.which(DOT_EXECUTABLE)
    if executable is None:
        return None
    try:
        done = subprocess.run([executable, "-Tplain"], input=dot_source.encode("utf-8"), capture_output=True,
                              timeout=DOT_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired):
        return None
    first = done.stdout.decode("utf-8", "replace").split("\n", 1)[0].split()
    if done.returncode != 0 or len(first) < 4 or first[0] != "graph":
        return None
    return float(first[2]), float(first[3])


def render(dot_source: str, path: str | Path, format: str, *, size: tuple[float, float] | None = None) -> None:
    """Lay out ``dot_source`` with Graphviz and write the picture to ``path``.

    The picture is written atomically: when ``dot`` is missing, fails or times out,
    an existing file at ``path`` keeps its content.

    Args:
        dot_source: DOT text, e.g. from :func:`to_dot`.
        path: the file to write.
        format: ``"svg"`` or ``"png"``.
        size: the largest the picture may be, ``(width, height)`` in inches (at 150
            dots per inch for PNG): a larger layout is scaled down to fit.

    Raises:
        DependencyNotInstalled: the ``dot`` program is not installed.
        PetriflowError: unknown format, missing output directory, or ``dot`` failed
            (the message carries the first line ``dot`` printed on standard error).
    """
    if format not in PICTURE_FORMATS:
        raise PetriflowError(f"cannot draw format {format!r}; use one of {', '.join(PICTURE_FORMATS)}")
    path = Path(path)
    _check_directory(path)
    executable = shutil.which(DOT_EXECUTABLE)
    if executable is None:
        raise DependencyNotInstalled(_MISSING_DOT)
    command = [executable, f"-T{format}"]
    if format == "png":
        command.append(f"-Gdpi={PNG_DPI}")
    if size is not None:
        command.append(f"-Gsize={size[0]:g},{size[1]:g}")
    try:
        done = subprocess.run(
            command, input=dot_source.encode("utf-8"), capture_output=True, timeout=DOT_TIMEOUT_S
        )
    except FileNotFoundError:
        raise DependencyNotInstalled(_MISSING_DOT) from None
    except subprocess.TimeoutExpired:
        raise PetriflowError(
            f"Graphviz 'dot' took longer than {DOT_TIMEOUT_S:g} s; {path} not written"
        ) from None
    if done.returncode != 0 or not done.stdout:
        lines = done.stderr.decode("utf-8", "replace").strip().splitlines()
        reason = lines[0].strip() if lines else f"exit status {done.returncode}"
        raise PetriflowError(f"Graphviz 'dot' failed: {reason}")
    _write(path, done.stdout)


def format_of(path: str | Path, format: str | None = None) -> str:
    """The export format for ``path``: ``format`` if given (it must agree with the
    file's ending when that names a format), else the one the ending names.

    Examples:
        >>> format_of("net.svg"), format_of("net.PNG"), format_of("net.txt", "dot")
        ('svg', 'png', 'dot')
        >>> format_of("net.svg", "png")
        Traceback (most recent call last):
        ...
        petriflow.errors.PetriflowError: net.svg: the file ends in .svg but the format asked for is png; name it .png or drop -f
    """
    ending = Path(path).suffix.lower().lstrip(".")
    ending = {"yml": "yaml", "gv": "dot", "xml": "pnml"}.get(ending, ending)
    if format is None:
        if ending not in EXPORT_FORMATS:
            raise PetriflowError(f"{path}: cannot tell the format from the ending {Path(path).suffix or '(none)'!r};"
                                 f" give -f {'|'.join(EXPORT_FORMATS)}")
        return ending
    if format not in EXPORT_FORMATS:
        raise PetriflowError(f"unknown export format {format!r}; use one of {', '.join(EXPORT_FORMATS)}")
    if ending in EXPORT_FORMATS and ending != format:
        raise PetriflowError(f"{path}: the file ends in .{Path(path).suffix.lower().lstrip('.')} but the format"
                             f" asked for is {format}; name it .{format} or drop -f")
    return format


def export_net(
    net: Net,
    path: str | Path,
    format: str | None = None,
    marking: Mapping[str, int] | None = None,
    highlight: Sequence[str] | None = None,
    *,
    caption: str | None = None,
    running: Mapping[str, Mapping[str, int]] | None = None,
    rankdir: str = "auto",
    size: tuple[float, float] | None = None,
    fold: bool | None = None,
) -> str | None:
    """Write ``net`` to ``path`` as ``pnml``, ``yaml``, ``dot``, ``svg`` or ``png``.

    Every format is written atomically, so a failure leaves an existing file as it was.
    A picture of every node of a net too big to read (more than
    :data:`~petriflow.fold.FOLD_ABOVE` nodes, not folded) is scaled down to fit
    :data:`FULL_SIZE` (or ``size``, when smaller).

    Returns:
        ``None``, or a one-line note on what was drawn differently from what was asked
        (a big net drawn in full and scaled down), for the caller to show.

    Args:
        net: the net.
        path: the output file; its directory must exist.
        format: one of :data:`EXPORT_FORMATS`; default: from the file's ending (a
            format that contradicts the ending is refused, see :func:`format_of`).
        marking: for pictures and DOT, the tokens to draw (default: the initial
            marking); for ``pnml``/``yaml``, the initial marking to write when it
            differs from the net's own.
        highlight: for pictures and DOT, node ids to highlight (see :func:`to_dot`);
            not used by ``pnml``/``yaml``.
        caption: for pictures and DOT, a line under the title.
        running: for pictures and DOT, running transitions and the tokens they hold.
        rankdir: ``LR``, ``TB``, or ``auto``: left to right unless that layout would be
            more than :data:`AUTO_RATIO` times wider than high, then top to bottom.
        size: for pictures, the largest size ``(width, height)`` in inches.
        fold: for pictures and DOT, draw one box per agent subnet
            (:mod:`petriflow.fold`); ``None``: fold a big team net
            (:func:`~petriflow.fold.should_fold`) unless something is highlighted or
            running; ``False``: every node.

    Raises:
        PetriflowError: unknown format, a format the file's ending contradicts,
            missing output directory, unknown node in ``marking``/``highlight``, or a
            failed write or layout.
        DependencyNotInstalled: a picture was asked for and Graphviz is missing.
    """
    format = format_of(path, format)
    if rankdir not in RANK_DIRECTIONS:
        raise PetriflowError(f"rankdir must be one of {', '.join(RANK_DIRECTIONS)}, got {rankdir!r}")
    path = Path(path)
    _check_directory(path)
    if format in ("pnml", "yaml"):
        from petriflow.io import save_net

        if marking is not None:
            chosen = net.check_marking(marking)
            if chosen != net.initial_marking:
                net = net.copy()
                net.set_initial_marking(chosen)
        try:
            save_net(net, path, format)
        except OSError as exc:
            raise PetriflowError(f"{path}: cannot write: {getattr(exc, 'strerror', None) or exc}") from None
        return None
    from petriflow.fold import FOLD_ABOVE, folded_dot, should_fold

    if fold is None:
        fold = not highlight and not running and should_fold(net)
    if fold:
        source = folded_dot(net, marking, rankdir="LR" if rankdir == "auto" else rankdir)
        if rankdir == "auto":
            extent = _layout_size(source)
            if extent is not None and extent[0] > AUTO_RATIO * extent[1]:
                source = folded_dot(net, marking, rankdir="TB")
        if format == "dot":
            _write(path, source.encode("utf-8"))
        else:
            render(source, path, format, size=size)
        return None
    nodes = len(net.places) + len(net.transitions)
    note = None
    if nodes > FOLD_ABOVE and format in PICTURE_FORMATS:
        bound = FULL_SIZE if size is None else (min(size[0], FULL_SIZE[0]), min(size[1], FULL_SIZE[1]))
        size = bound
        pixels = f" ({bound[0] * PNG_DPI:.0f} x {bound[1] * PNG_DPI:.0f} px)" if format == "png" else ""
        note = (f"{net.id}: {nodes} nodes are too many to read drawn in full; the picture is scaled down to"
                f" at most {bound[0]:g} x {bound[1]:g} in{pixels}"
                + ("; --fold draws one box per agent" if len(net.subnets) >= 2 else ""))
    options = {"highlight": highlight, "caption": caption, "running": running}
    source = to_dot(net, marking, rankdir="LR" if rankdir == "auto" else rankdir, **options)
    if rankdir == "auto":
        extent = _layout_size(source)
        if extent is not None and extent[0] > AUTO_RATIO * extent[1]:
            source = to_dot(net, marking, rankdir="TB", **options)
    if format == "dot":
        _write(path, source.encode("utf-8"))
    else:
        render(source, path, format, size=size)
    return note
