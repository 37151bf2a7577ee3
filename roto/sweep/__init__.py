"""``roto sweep``: Optuna studies over agent (and env) settings, from one process to many machines.

Modules: ``space`` (search spaces as YAML), ``study`` (settings, sampler, pruner), ``trial`` (a
trial is an ordinary training run), ``worker`` (claim, train, tell), ``report`` (export, show),
``command`` (the CLI). Storage, claims and retries are the job queue's (``roto.jobs``), shared with
``roto olympiad``.
"""
