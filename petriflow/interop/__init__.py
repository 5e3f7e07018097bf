"""Conversions to and from other Petri-net libraries."""
