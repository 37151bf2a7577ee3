"""Format versions of the files roto writes and reads back: checkpoints, run configs, cell
summaries, banks of recorded states and submissions each carry ``format``; a reader refuses a format it does
not know in one line, instead of misreading a file a newer roto wrote. A file without the entry
predates format versions and has format 1's layout.
"""

from __future__ import annotations

from types import MappingProxyType

FORMAT_KEY = "format"
FORMATS = MappingProxyType({"checkpoint": 3, "run config": 3, "cell summary": 1, "bank": 1, "submission": 1})
"""{kind of file: the format this roto writes (and the newest it reads)}. Checkpoints and run
configs: 2, the env's training aids in one ``aids`` section (format 1 held them as flat env fields;
``roto.envs.aids.settings.aids_from_legacy_fields`` reads them); 3, the run's ``RunSpec`` (env,
agent, steps) where formats 1 and 2 had a ``train`` section (env, total_steps) beside the agent
(``roto.rl.run_spec.spec_data`` reads them)."""


def format_stamp(kind: str) -> dict[str, int]:
    """The entry a ``kind`` file carries: {"format": its format}."""
    return {FORMAT_KEY: FORMATS[kind]}


def check_format(kind: str, found: object, where: str) -> None:
    """Refuse ``found``, the format entry of the ``kind`` file ``where`` names (None: no entry),
    unless this roto reads it.

    Raises:
        ValueError naming the file, the format found and the formats this roto reads.
    """
    if found is None:
        return
    known = FORMATS[kind]
    if isinstance(found, bool) or not isinstance(found, int) or not 1 <= found <= known:
        raise ValueError(
            f"{where} is a {kind} of format {found!r}; this roto reads {kind} formats 1 to {known} "
            "(a newer roto wrote it? update roto)"
        )
