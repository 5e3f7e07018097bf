"""Properties of nets: CTL, LTL, reachability and bounds, checked and watched at run time."""
