"""The results reference's tables (docs/results.md, the README), generated from cell summaries.

``task_table``: one row per (hand, obs mode, variant) of a task: the config it trained, the seeds,
the task's lead measure (Baoding: round rotations; Bounce: bounces) as mean ± std, IQM with its
95 % interval and per-seed values, roto's swap count beside Baoding's, the hand's reference and
roto's published figures on the Shadow. ``overview_table``: the README's few lines, hands by
(task, obs mode). ``orderings_table``: per (task, hand) the gaps state − blind and touch's effect
(blind − proprio) with their intervals, and whether state ≥ blind ≥ proprio holds.
``seeds_table``: Baoding's seeds one by one. ``variants_table``: each variant beside a baseline
variant on the seeds both trained (a study's ablations or candidates).
A page's generated blocks of these tables: ``roto.olympiad.page_blocks``.
"""

from __future__ import annotations

import numpy as np

from roto.envs.observations import OBS_MODES
from roto.olympiad.cell import cell_spec
from roto.olympiad.never_armed import aid_labels
from roto.olympiad.path_results import kind_counts, measure_scores, seed_measures, seed_path_kind, with_derived_means
from roto.olympiad.plan import Cell, Plan
from roto.olympiad.results import cell_statistics, lead_measure
from roto.olympiad.stats import difference_ci, paired_difference_ci
from roto.robots import ROBOTS
from roto.tasks import TASKS, get_task

PUBLISHED = {
    ("bounce", "blind"): "v1 PPO 69; 2.0 about 80",
    ("bounce", "proprio"): "v1 PPO 53",
    ("bounce", "state"): "2.0 close to 100",
    ("baoding", "blind"): "v1 PPO 5.1 (rotations); 2.0 up to 13 (best seed)",
    ("baoding", "proprio"): "v1 PPO 0.1 (rotations)",
    ("baoding", "state"): "2.0 up to 35",
}
"""roto's published Shadow figures at 200 M env steps by (task, obs mode) (docs/spec.md §9): roto
v1's PPO (mean of 5 seeds) and the roto 2.0 paper; other agents than roto's, set beside ours."""

Row = tuple[str, str, str]  # robot, obs, variant


def _row_order(row: Row) -> tuple[int, int, str]:
    robots, modes = list(ROBOTS), list(OBS_MODES)
    robot, obs, variant = row
    return (robots.index(robot) if robot in robots else len(robots), modes.index(obs), variant)


def config_label(summary: dict, plan: Plan | None = None) -> str:
    """The config a cell trained: with ``plan``, the config and overrides the plan trains its hand
    with; else the label its summary records, else its variant's name."""
    task, variant = summary["task"], summary["variant"]
    if plan is not None and variant in plan.variants:
        config, overrides = plan.variants[variant].agent_for(task, summary["robot"])
        config = config or f"{task} (roto's)"
        return " + ".join([config, ", ".join(overrides)] if overrides else [config])
    return (summary.get("agent") or {}).get("label") or variant


def training_aids(summary: dict, plan: Plan | None = None) -> str:
    """The training aids a cell's run trained with: as its summary records them, else as ``plan``
    trains the cell, else "not recorded"; "none" when it used none; round swaps that never armed
    (``roto.olympiad.never_armed``) named so."""
    if "training_aids" in summary:
        names = sorted(summary["training_aids"])
    elif plan is not None and summary["variant"] in plan.variants:
        cell = Cell.of_summary(summary)
        names = sorted(cell_spec(plan, cell).env.aids.active())
    else:
        return "not recorded"
    return ", ".join(aid_labels(names, summary)) or "none"


def _statistics(scores: np.ndarray | None) -> tuple[str, str, str]:
    """(mean ± std, IQM [95 % interval], per-seed values) of one row's seeds."""
    if scores is None:
        return "not measured", "", ""
    stats = cell_statistics(scores)
    per_seed = ", ".join(f"{v:.1f}" for v in scores)
    if stats["n"] == 1:
        return f"{stats['mean']:.1f}", "", per_seed
    if stats["n"] < 3:  # an IQM and interval of one or two values say nothing more than the values
        return f"{stats['mean']:.1f} ± {stats['std']:.1f}", "", per_seed
    interval = f"{stats['iqm']:.1f} [{stats['iqm_low']:.1f}, {stats['iqm_high']:.1f}]"
    return f"{stats['mean']:.1f} ± {stats['std']:.1f}", interval, per_seed


def task_table(summaries: list[dict], task: str, plan: Plan | None = None) -> str:
    """Markdown: one row per (hand, obs mode, variant) of ``task`` in ``summaries`` (best policies,
    the evaluation episodes' mean per seed), each naming its config (``plan``: as that plan trains it)."""
    spec, lead = get_task(task), lead_measure(task)
    scores = measure_scores(summaries, task, lead)
    count = measure_scores(summaries, task, spec.headline_metric) if lead != spec.headline_metric else None
    labels: dict[Row, str] = {}
    seeds: dict[Row, list[int]] = {}
    aids: dict[Row, set[str]] = {}
    kinds: dict[Row, list[str | None]] = {}
    for s in (s for s in summaries if s["task"] == task):
        row = (s["robot"], s["obs"], s["variant"])
        labels.setdefault(row, config_label(s, plan))
        seeds.setdefault(row, []).append(s["seed"])
        aids.setdefault(row, set()).add(training_aids(s, plan))
        kinds.setdefault(row, []).append(seed_path_kind(task, s))
    counts = {row: kind_counts(k) for row, k in kinds.items()}
    with_kinds = any(counts.values())
    head = ["hand", "obs", "agent config", "training aids", "seeds", f"{lead}: mean ± std", "IQM [95 % CI]", "per seed"]
    head += ["seeds by path"] if with_kinds else []
    head += [f"roto's {spec.headline_metric}"] if count is not None else []
    head += [f"{spec.reference_name} ({spec.headline_metric})", "roto published (Shadow, 200 M)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in sorted(scores, key=_row_order):
        robot, obs, _ = row
        cells = [robot, obs, f"`{labels[row]}`", "; ".join(sorted(aids[row])), ", ".join(map(str, sorted(seeds[row])))]
        cells += _statistics(scores[row])
        cells += [counts[row]] if with_kinds else []
        if count is not None:
            cells.append(_statistics(count[row])[0])
        cells.append(f"{spec.reference[robot]}" if robot in spec.reference else "")
        cells.append(PUBLISHED.get((task, obs), "") if robot == "shadow" else "")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def lead_by_mode(summaries: list[dict]) -> dict[tuple[str, str, str], list[np.ndarray]]:
    """{(task, robot, obs): each variant's (seeds,) lead measure (``lead_measure``) of its best
    policies}, variants whose summaries did not measure it left out; in task and hand order."""
    found: dict[tuple[str, str, str], list[np.ndarray]] = {}
    for task in [t for t in TASKS if any(s["task"] == t for s in summaries)]:
        scores = measure_scores(summaries, task, lead_measure(task))
        for row in sorted(scores, key=_row_order):
            if scores[row] is not None:
                found.setdefault((task, row[0], row[1]), []).append(scores[row])
    return found


def overview_table(summaries: list[dict]) -> str:
    """Markdown for the README: a row per hand and task, a column per obs mode (so the header stays
    short and four hands by two tasks take ten lines), each cell the task's lead measure
    (``lead_measure``: bounces, Baoding's round rotations) as the mean over seeds of the best
    policies, and the seed count."""
    found = lead_by_mode(summaries)
    modes, rows = {obs for _, _, obs in found}, {(task, robot) for task, robot, _ in found}
    columns = [obs for obs in OBS_MODES if obs in modes]
    robots = sorted({robot for _, robot, _ in found}, key=lambda r: _row_order((r, "blind", "")))
    lines = ["| " + " | ".join(["hand", "task", *columns]) + " |", "|" + "---|" * (len(columns) + 2)]
    for robot in robots:
        for task in [t for t in TASKS if (t, robot) in rows]:
            seeds = [found.get((task, robot, obs), []) for obs in columns]
            cells = [" / ".join(f"{v.mean():.1f} (n={v.size})" for v in values) for values in seeds]
            lines.append("| " + " | ".join([robot, task, *cells]) + " |")
    return "\n".join(lines)


def _pooled(found: dict[tuple[str, str, str], list[np.ndarray]], task: str, robot: str, obs: str) -> np.ndarray | None:
    """Every seed of every variant of one (task, hand, obs mode), or None where it has none."""
    return np.concatenate(found[(task, robot, obs)]) if (task, robot, obs) in found else None


def _gap(x: np.ndarray | None, y: np.ndarray | None) -> tuple[str, str]:
    """(mean(x) − mean(y), its 95 % bootstrap interval once each side has three seeds or more);
    blank where a side has no seeds."""
    if x is None or y is None:
        return "", ""
    interval = "needs three seeds each"
    if min(x.size, y.size) >= 3:
        interval = "[{:.1f}, {:.1f}]".format(*difference_ci(x, y))
    return f"{x.mean() - y.mean():+.1f}", interval


ORDER = ("state", "blind", "proprio")
"""The paper's ordering of the obs modes on every task and hand: seeing the balls' state beats touch,
touch beats proprioception alone."""


def orderings_table(summaries: list[dict]) -> str:
    """Markdown: per (task, hand) with a blind agent and a state-based or proprio-only one, each obs
    mode's lead measure (best policies, mean over seeds, variants pooled; "none" for a mode without
    seeds), the gaps state − blind and blind − proprio with 95 % bootstrap intervals where both sides
    have seeds, and whether the means keep the paper's order (``ORDER``), which pair breaks it, or,
    with a mode missing, the part of the order measured so far."""
    found = lead_by_mode(summaries)
    lines = [
        "| task | hand | state (seeds) | blind (seeds) | proprio (seeds) | state − blind | 95 % CI "
        "| blind − proprio | 95 % CI | state ≥ blind ≥ proprio |",
        "|" + "---|" * 10,
    ]
    for task, robot in dict.fromkeys((task, robot) for task, robot, _ in found):  # lead_by_mode's order
        modes = [_pooled(found, task, robot, obs) for obs in ORDER]
        if modes[1] is None or (modes[0] is None and modes[2] is None):
            continue
        cells = [task, robot, *(f"{m.mean():.1f} ({m.size})" if m is not None else "none" for m in modes)]
        cells += [*_gap(modes[0], modes[1]), *_gap(modes[1], modes[2]), _order_verdict(modes)]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _order_verdict(modes: list[np.ndarray | None]) -> str:
    """ "holds", the pairs of ``ORDER`` whose means break it, or, with a mode missing, the measured
    pair that holds ("blind ≥ proprio (no state)")."""
    pairs = [(ORDER[i], ORDER[i + 1], modes[i], modes[i + 1]) for i in range(len(ORDER) - 1)]
    measured = [(a, b, x, y) for a, b, x, y in pairs if x is not None and y is not None]
    broken = [f"{a} < {b}" for a, b, x, y in measured if x.mean() < y.mean()]
    if broken or len(measured) == len(pairs):
        return "; ".join(broken) or "holds"
    missing = ", ".join(obs for obs, m in zip(ORDER, modes, strict=True) if m is None)
    return "; ".join(f"{a} ≥ {b}" for a, b, _, _ in measured) + f" (no {missing})"


FIRST = (1.0, 5.0)
"""The lead measure's levels whose first evaluation round ``seeds_table`` names (Baoding: round rotations)."""


def _first_reaching(evaluations: list[dict], key: str, level: float) -> str:
    steps = next((r["env_steps"] for r in evaluations if r.get(key, float("-inf")) >= level), None)
    return "never" if steps is None else f"{steps / 1e6:.2f} M"


def seeds_table(summaries: list[dict]) -> str:
    """Markdown: one row per seed (cell) of the tasks that lead with a measure of their own
    (Baoding): its best policy's lead measure ± std over episodes, roto's count, the path metrics,
    the env steps of the first training-time evaluation reaching each of ``FIRST``, and the
    training time."""
    lines = []
    for task in [t for t in TASKS if get_task(t).selection_metric and any(s["task"] == t for s in summaries)]:
        spec, lead = get_task(task), lead_measure(task)
        paths = [name for name in spec.path_metric_names if name != lead]
        head = ["cell", "seed", lead, f"roto's {spec.headline_metric}", *paths, "path"]
        head += [f"first evaluation ≥ {level:g}" for level in FIRST] + ["env steps", "training"]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        rows = sorted(
            (s for s in summaries if s["task"] == task),
            key=lambda s: (_row_order((s["robot"], s["obs"], s["variant"])), s["seed"]),
        )
        for s in rows:
            best = with_derived_means(task, s["best"])

            def value(name: str, best: dict = best) -> str:
                return f"{best[f'{name}_mean']:.2f}" if f"{name}_mean" in best else "not measured"

            cells = [f"{s['robot']} / {s['obs']} / {s['variant']}", str(s["seed"])]
            spread = f" ± {best[f'{lead}_std']:.2f}" if f"{lead}_std" in best else ""
            cells += [f"**{value(lead)}**{spread}", value(spec.headline_metric), *(value(name) for name in paths)]
            cells.append(seed_path_kind(task, s) or "not measured")
            cells += [_first_reaching(s["evaluations"], f"{lead}_mean", level) for level in FIRST]
            minutes = f"{s['train_wall_s'] / 60:.0f} min" if "train_wall_s" in s else ""
            cells += [f"{s.get('env_steps', 0) / 1e6:.1f} M", minutes]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _against(values: dict[int, float], base: dict[int, float]) -> list[str]:
    """(shared seeds, paired difference with its 95 % interval, seeds better / worse) of one
    variant's seeds against the baseline's."""
    shared = sorted(set(values) & set(base))
    if not shared:
        return ["none", "", ""]
    x, y = np.array([values[s] for s in shared]), np.array([base[s] for s in shared])
    difference = f"{(x - y).mean():+.1f}"
    interval = "[{:.1f}, {:.1f}]".format(*paired_difference_ci(x, y)) if len(shared) >= 3 else "needs 3 shared seeds"
    return [", ".join(map(str, shared)), f"{difference} {interval}", f"{int((x > y).sum())} / {int((x < y).sum())}"]


def variants_table(summaries: list[dict], baseline: str, plan: Plan | None = None) -> str:
    """Markdown: per (task, hand, obs mode) that has the ``baseline`` variant and another, the
    baseline and then every other, each with its config, seeds, lead measure (mean ± std, per
    seed), seeds by path (Baoding), and against the baseline on the seeds both trained: the mean
    paired difference with its 95 % bootstrap interval (three shared seeds or more) and how many
    seeds did better and worse. A change is judged on the same seeds, seed by seed, not only by
    its mean. With ``plan``, only the variants it trains: a folder may hold another study's cells."""
    if plan is not None:
        summaries = [s for s in summaries if s["variant"] in plan.variants]
    head = ["task", "hand", "obs", "variant", "agent config", "seeds", "mean ± std", "per seed", "seeds by path"]
    head += [f"seeds shared with {baseline}", "paired difference [95 % CI]", "seeds better / worse"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for task in [t for t in TASKS if any(s["task"] == t for s in summaries)]:
        measured = seed_measures(summaries, task, lead_measure(task)).items()
        values = {row: {seed: v for seed, v in seeds.items() if v is not None} for row, seeds in measured}
        labels = {(s["robot"], s["obs"], s["variant"]): config_label(s, plan) for s in summaries if s["task"] == task}
        kinds: dict[Row, list[str | None]] = {}
        for s in (s for s in summaries if s["task"] == task):  # counted, so in any order
            kinds.setdefault((s["robot"], s["obs"], s["variant"]), []).append(seed_path_kind(task, s))
        for robot, obs in dict.fromkeys((r, o) for r, o, v in sorted(values, key=_row_order) if v == baseline):
            rows = sorted((row for row in values if row[:2] == (robot, obs)), key=lambda r: (r[2] != baseline, r[2]))
            if len(rows) == 1:  # the baseline alone: nothing to set beside it
                continue
            for row in rows:
                seeds = values[row]
                scores = np.array([seeds[s] for s in sorted(seeds)])
                cells = [task, robot, obs, row[2], f"`{labels[row]}`", ", ".join(map(str, sorted(seeds)))]
                cells += [f"{scores.mean():.1f} ± {scores.std():.1f}", ", ".join(f"{v:.1f}" for v in scores)]
                cells.append(kind_counts(kinds[row]))
                base = values[(robot, obs, baseline)]
                cells += ["(baseline)", "", ""] if row[2] == baseline else _against(seeds, base)
                lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)
