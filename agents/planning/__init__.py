"""Path planning on grid maps (A*), path tracking and collision avoidance."""
