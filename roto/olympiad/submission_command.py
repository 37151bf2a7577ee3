"""``roto submit`` (a submission from ``roto eval``'s files, one per training seed) and ``roto
results``' flags for submissions: ``--check FILE`` and ``--submissions FOLDER``."""

from __future__ import annotations

import argparse
import json
import sys

from roto.cli_errors import check_output_file, make_parents


def add_submit_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``roto submit``."""
    p = sub.add_parser(
        "submit",
        help="bundle roto eval's files (one per training seed) into a submission for roto's table",
    )
    p.add_argument("evaluations", nargs="+", help="roto eval's JSON files, one per training seed")
    p.add_argument("--method", required=True, help="the method's column name (a-z, 0-9, '_', '.', '-')")
    p.add_argument("--description", required=True, help="what the method is and what it trained with")
    p.add_argument("--env_steps", type=int, required=True, help="the training budget of each seed, in env steps")
    p.add_argument("--url", default=None, help="where the method is described (optional)")
    p.add_argument("--out", required=True, help="the submission's JSON file")
    p.set_defaults(func=cmd_submit)


def add_results_submission_flags(p: argparse.ArgumentParser) -> None:
    """``roto results``' flags for submissions."""
    p.add_argument("--submissions", default=None, help="a folder of submissions to set beside the baselines")
    p.add_argument("--check", default=None, metavar="FILE", help="check one submission and exit (nothing written)")


def cmd_check(path: str) -> int:
    """``roto results --check FILE``: the submission's cell and seeds, or its first error."""
    from roto.olympiad.submission import read_submission

    data = read_submission(path)
    cell = {key: data[key] for key in ("task", "task_version", "robot", "obs", "touch", "env_steps")}
    seeds = [entry["seed"] for entry in data["seeds"]]
    print(json.dumps({"submission": path, "valid": True, "method": data["method"]["name"], **cell, "seeds": seeds}))
    return 0


def evaluation_config(path: str, data: object):
    """The env config a ``roto eval`` file names, with the training seed it evaluated."""
    from roto.envs.config import EnvConfig
    from roto.olympiad.results import json_kind

    if not isinstance(data, dict):
        raise ValueError(f"{path!r} holds {json_kind(data)}: not a file of roto eval")
    missing = [key for key in ("task", "robot", "obs", "touch", "train_seed", "per_episode") if key not in data]
    if missing:
        raise ValueError(f"{path!r} lacks {missing}: not a file of roto eval (of this roto: run roto eval again)")
    touch = data["touch"] if data["obs"] != "proprio" else "binary"
    return EnvConfig(task=data["task"], robot=data["robot"], obs_mode=data["obs"], touch=touch), data["train_seed"]


def cmd_submit(args: argparse.Namespace) -> int:
    """Write the submission of ``args.evaluations``, checked, to ``args.out``."""
    from roto.olympiad.submission import make_submission
    from roto.result_files import read_json, write_text_atomic

    out = check_output_file(args.out, "--out", example="submission.json")
    results, configs = {}, set()
    for path in args.evaluations:
        data = read_json(path, "roto eval file")
        config, seed = evaluation_config(path, data)
        if seed in results:
            raise ValueError(f"{path!r} evaluates training seed {seed} again; give one file per training seed")
        results[seed] = data
        configs.add((config.task, config.robot, config.obs_mode, config.touch))
    if len(configs) > 1:
        raise ValueError(f"the files evaluate different cells {sorted(configs)}; a submission is one (task, hand, obs)")
    method = {"name": args.method, "description": args.description, **({"url": args.url} if args.url else {})}
    submission = make_submission(config, results, method, args.env_steps)
    write_text_atomic(make_parents(out), json.dumps(submission, indent=1))
    print(json.dumps({"submission": str(out), "method": args.method, "seeds": sorted(results)}))
    print(f"wrote {out}", file=sys.stderr)
    return 0
