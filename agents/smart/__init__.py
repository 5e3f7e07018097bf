"""The SMART scenario (seed 003): command messages and the actions that tie vision,
planning and gaits to its workflow net."""
