"""Watching and steering a run while it goes: ``petriflow run NET --live`` and ``petriflow ctl``.

:mod:`petriflow.live.server` serves the live page and takes its controls over a
WebSocket; :mod:`petriflow.live.state` keeps what the page shows; :mod:`petriflow.live.page`
makes the page; :mod:`petriflow.live.ctl` is the command-line client. The controls
themselves (the queue the scheduler reads between firings, the breakpoints) are the
runtime's: :mod:`petriflow.runtime.control`.
"""
