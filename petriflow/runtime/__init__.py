"""Running nets: actions, the registry, the scheduler, channels, trace and journal."""
