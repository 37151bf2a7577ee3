"""Reference controllers that may read the simulator's full state: what each hand can do on a task."""
