"""Putting a page together: the template, the inlined scripts and styles, the data.

Everything a page needs is inside it: the vendored libraries (``assets/``, each with
its licence) and the page's own script and style are inlined, and the data goes in a
``<script type="application/json">`` block. Large data (a run's trace) is gzip
compressed and base64 encoded; the page inflates it with the browser's own
``DecompressionStream``. Nothing is fetched when the page opens.
"""

from __future__ import annotations

import base64
import gzip
import html
import json
from importlib import resources
from typing import Any

__all__ = ["asset", "pack", "pack_bytes", "render"]


def asset(name: str) -> str:
    """The text of a file of ``petriflow/view/assets``."""
    return resources.files("petriflow.view").joinpath("assets", name).read_text(encoding="utf-8")


def pack(text: str) -> str:
    """``text`` gzip-compressed (no time stamp, so equal input gives equal bytes) and
    base64-encoded.

    Examples:
        >>> import base64, gzip
        >>> gzip.decompress(base64.b64decode(pack("abc"))).decode()
        'abc'
    """
    return pack_bytes(text.encode("utf-8"))


def pack_bytes(data: bytes) -> str:
    """``data`` gzip-compressed (no time stamp) and base64-encoded."""
    return base64.b64encode(gzip.compress(data, compresslevel=9, mtime=0)).decode("ascii")


def _script_json(data: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``</`` can close it early)."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False, ensure_ascii=False)
    return text.replace("</", "<\\/").replace("<!--", "<\\u0021--")


def _inline_script(code: str) -> str:
    return "<script>\n" + code.replace("</script", "<\\/script") + "\n</script>"


def render(*, title: str, body: str, data: Any, scripts: list[str], styles: list[str],
           connect: bool = False) -> str:
    """The whole page: ``body`` (HTML), ``data`` as JSON in ``#pf-data``, the named
    assets inlined (scripts in order, after the body). ``connect``: the page may open
    connections to the server it came from (a live page's WebSocket), and nowhere else."""
    allowed = "; connect-src 'self'" if connect else ""
    style_text = "\n".join(asset(name) for name in styles)
    script_text = "\n".join(_inline_script(asset(name)) for name in scripts)
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline';"
        f" style-src 'unsafe-inline'; img-src data:{allowed}\">\n"
        f"<title>{html.escape(title)}</title>\n<style>\n{style_text}\n</style>\n</head>\n<body>\n{body}\n"
        f"<script type=\"application/json\" id=\"pf-data\">{_script_json(data)}</script>\n"
        f"{script_text}\n</body>\n</html>\n"
    )
