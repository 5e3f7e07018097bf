"""Agent actions (planning, gait, bidding, communication), installed as ``petriflow.agents``."""
