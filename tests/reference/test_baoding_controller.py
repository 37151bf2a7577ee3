"""The Baoding reference controller: it swaps from the pre-swap states it recorded, and refuses
envs it cannot plan for."""

import pathlib

import numpy as np
import pytest
import torch

from roto.envs.aids.replayed_starts import ReplayedStarts
from roto.reference.baoding_controller import (
    BaodingReference,
    PreswapStates,
    reference_env,
    run_reference_baoding,
    run_reference_episode,
    save_preswap_states,
)
from roto.reference.baoding_cost import BaodingCostWeights
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig
from roto.registry import make

PRESWAP = pathlib.Path(__file__).resolve().parents[2] / "roto/banks/shadow_preswap.npz"


def controller_for(env, seed: int = 0) -> BaodingReference:
    lo, hi = env.indices.ctrl_lo.numpy(), env.indices.ctrl_hi.numpy()
    planner = PredictiveSampling(env.model, lo, hi, SamplingConfig(threads=1, seed=seed))
    return BaodingReference(env, planner, BaodingCostWeights())


@pytest.mark.parametrize("seed", [0, 5])
def test_from_a_recorded_preswap_state_the_controller_swaps_again(seed):
    """The recorded states fit the Shadow's scene and lead to a swap within a few tenths of a second
    (recorded 10 control steps before one), with a planner seeded afresh. The env starts in one of
    them through its own replayed starts."""
    with np.load(PRESWAP) as saved:
        assert set(np.atleast_1d(saved["lead_steps"])) == {10} and len(saved["physics"]) >= 100
    env = reference_env("shadow", seed=seed, aids={"replayed_starts": {"bank": str(PRESWAP), "share": 1.0}})
    env.reset()
    physics = torch.from_numpy(env.backend.physics_state()[0, 1 : 1 + env.model.nq])
    assert (env.aid(ReplayedStarts).bank.qpos == physics).all(dim=1).any()  # a recorded state, exactly
    controller = controller_for(env)
    controller.start()
    swaps = 0
    for _ in range(40):
        _, _, terminated, _, info = env.step(controller.act())
        swaps += int(info["reward_terms"]["swap"][0] > 0)
        if swaps or bool(terminated[0]):
            break
    controller.planner.close()
    env.close()
    assert swaps == 1


def test_a_reference_episode_reports_the_turns_of_the_ball_pair_over_its_own_steps():
    """The path metrics of a short episode started just before a swap: the pair turns while it swaps."""
    env = reference_env(
        "shadow", seed=0, episode_steps=30, aids={"replayed_starts": {"bank": str(PRESWAP), "share": 1.0}}
    )
    controller = controller_for(env)
    try:
        result = run_reference_episode(controller)
    finally:
        controller.planner.close()
        env.close()
    assert result["length"] == 30 and result["swaps"] >= 1
    assert 0.0 < result["net_turns"] <= result["travelled_turns"] + 1e-12
    assert result["round_rotations"] == min(result["rotations"], result["net_turns"])


def test_the_controller_needs_one_world_on_the_cpu():
    env = make("baoding", robot="shadow", num_envs=2)
    with pytest.raises(ValueError, match="one-world env on the cpu backend"):
        controller_for(env)
    env.close()


def test_preswap_states_of_another_hand_are_refused():
    with pytest.raises(ValueError, match="states recorded on robot 'shadow', not this env's 'allegro'"):
        reference_env("allegro", seed=0, aids={"replayed_starts": {"bank": str(PRESWAP), "share": 1.0}})


def test_preswap_states_are_recorded_at_each_lead_the_history_reaches(tmp_path):
    """At a swap, the state ``lead`` steps before it for each lead (history[-1]: 1 step before);
    a lead longer than the episode so far is skipped; the file keeps each row's lead."""
    history = [
        (np.full(3, k, dtype=float), np.full(2, -k, dtype=float), k % 2 == 0, np.array([k > 1, False]))
        for k in range(6)
    ]
    states = PreswapStates()
    states.record(history, (1, 3, 6, 7))
    assert states.lead == [1, 3, 6] and [int(p[0]) for p in states.physics] == [5, 3, 0]
    assert [int(t[0]) for t in states.target] == [-5, -3, 0] and states.swapped == [False, False, True]
    path = tmp_path / "bank.npz"
    save_preswap_states(path, "allegro", states)
    with np.load(path) as saved:
        assert saved["lead_steps"].tolist() == [1, 3, 6] and saved["physics"].shape == (3, 3)
        assert saved["latched"].tolist() == [[True, False], [True, False], [False, False]]


@pytest.mark.parametrize("leads", [(), (0,), (10, True)])
def test_bad_preswap_leads_are_refused_naming_them(leads):
    with pytest.raises(ValueError, match="preswap_leads must be control steps"):
        run_reference_baoding("shadow", episodes=1, preswap_leads=leads)
