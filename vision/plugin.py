"""Registers the actions of ``petriflow.vision`` (the ``petriflow.actions`` entry point).

Targets are lazy ``"module:Class"`` strings: OpenCV and NumPy are imported only when a
net binds one of these actions.

Examples:
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(load_plugins=False)
    >>> register(registry)
    >>> [name for name in registry.names() if name.startswith("vision.")]
    ['vision.capture', 'vision.locate']
"""

from __future__ import annotations

__all__ = ["register", "ACTIONS"]

ACTIONS = {
    "vision.capture": ("petriflow.vision.capture:Capture",
                       "render one camera frame when the transition fires"),
    "vision.locate": ("petriflow.vision.pipeline:Locate", "robots' poses and obstacles from the last frame"),
}


def register(registry) -> None:
    """Register every action of this package in ``registry``."""
    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
