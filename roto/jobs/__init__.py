"""The job queue that ``roto sweep`` and ``roto olympiad`` share: Optuna's storage as a list of jobs
(trials) that workers on one machine or many claim, heartbeat, finish, and retry when a worker dies.

Modules: ``storage`` (a journal file or a database, heartbeats, stale jobs, retries),
``journal`` (a journal file safe against a torn last line), ``retrying_storage`` (rides out a
database restart), ``claims`` (run a claimed job, launch worker processes), ``optuna_ids`` (the one
place Optuna's private trial id is read).
"""
