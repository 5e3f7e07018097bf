"""A swarm of kinematic robots exploring a large maze and sharing maps by radio (see nets/swarm)."""
