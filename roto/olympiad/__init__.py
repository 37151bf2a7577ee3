"""``roto olympiad``: train and evaluate a grid of hands x tasks x obs modes x agents x seeds, on one
machine or many, and ``roto results``: its tables and learning curves.

Modules: ``plan`` (plans as YAML, checked), ``cell`` (one cell's run, evaluations and summary),
``worker`` (cells handed out through an Optuna study), ``stats`` (IQM, bootstrap, probability of
improvement), ``results`` (tables, CSV, plots), ``command`` (the CLI).
"""
