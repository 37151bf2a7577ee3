"""``roto sweep``: Optuna studies over agent (and env) settings, from one process to many machines.

Modules: ``space`` (search spaces as YAML), ``study`` (settings, sampler, pruner), ``storage``
(journal or database, heartbeats), ``trial`` (a trial is an ordinary training run), ``worker``
(claim, train, tell), ``report`` (export, show), ``command`` (the CLI).
"""
