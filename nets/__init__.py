"""The scenarios shipped with petriflow (installed as ``petriflow.nets``; find them with
:mod:`petriflow.examples`). One folder per scenario: its nets, world, run configuration
and README. This file only makes the folder installable as package data."""
