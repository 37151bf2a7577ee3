"""Record Bounce's task version in the summaries trained before summaries recorded it, where
rollout_digest.py found the task at their training commits bit-identical to today's version.

    python experiments/bounce_task_version/stamp.py CHECKED_AT SUMMARY.json ...

Run at ``CHECKED_AT``, the commit the rollouts were compared against: each summary gains
``task_version`` (this checkout's Bounce version) and ``task_version_check``
saying how it was established; a summary that already records a version is refused.
"""

import json
import pathlib
import sys

from roto.tasks import get_task


def main(checked_at: str, paths: list[str]) -> None:
    version = get_task("bounce").version  # this checkout's: run it at the commit compared against
    for path in map(pathlib.Path, paths):
        summary = json.loads(path.read_text())
        if summary["task"] != "bounce" or "task_version" in summary:
            raise SystemExit(f"{path}: a Bounce summary without a task version expected")
        summary["task_version"] = version
        summary["task_version_check"] = (
            f"rollouts at {summary['commit']} bit-identical to v{version}'s at {checked_at} "
            "(experiments/bounce_task_version)"
        )
        path.write_text(json.dumps(summary, indent=1))  # as roto.olympiad.cell writes them
        print(f"{path.name}: v{version}, {summary['task_version_check']}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
