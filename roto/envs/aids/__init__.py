"""Training aids: what the env config's ``aids`` section (``roto.envs.aids.settings``) switches
on, each behind the ``TrainingAid`` protocol (``roto.envs.aids.protocol``), built in the section's
order by ``roto.envs.aids.build``. Adding an aid touches this folder and its tests only
(docs/developer.md). The package imports nothing itself, so the env config can read the section's
settings without loading the aids."""
