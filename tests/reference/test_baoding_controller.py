"""The Baoding reference controller: it swaps from the pre-swap states it recorded, and refuses
envs it cannot plan for."""

import pathlib

import numpy as np
import pytest
import torch

from roto.reference.baoding_controller import BaodingReference, reference_env
from roto.reference.baoding_cost import BaodingCostWeights
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig
from roto.registry import make

PRESWAP = pathlib.Path(__file__).resolve().parents[2] / "benchmarks/results/baoding_reference/shadow_preswap.npz"


def controller_for(env, seed: int = 0) -> BaodingReference:
    lo, hi = env._idx.ctrl_lo.numpy(), env._idx.ctrl_hi.numpy()
    planner = PredictiveSampling(env.model, lo, hi, SamplingConfig(threads=1, seed=seed))
    return BaodingReference(env, planner, BaodingCostWeights())


@pytest.mark.parametrize("seed", [0, 5])
def test_from_a_recorded_preswap_state_the_controller_swaps_again(seed):
    """The recorded states fit the Shadow's scene and lead to a swap within a few tenths of a second
    (recorded 10 control steps before one), with a planner seeded afresh. The env starts in one of
    them through its own replayed starts."""
    with np.load(PRESWAP) as saved:
        assert int(saved["lead_steps"]) == 10 and len(saved["physics"]) >= 100
    env = reference_env("shadow", seed=seed, replay_starts=str(PRESWAP), replay_share=1.0)
    env.reset()
    physics = torch.from_numpy(env.backend.physics_state()[0, 1 : 1 + env.model.nq])
    assert (env.replay_bank.qpos == physics).all(dim=1).any()  # a recorded state, exactly
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


def test_the_controller_needs_one_world_on_the_cpu():
    env = make("baoding", robot="shadow", num_envs=2)
    with pytest.raises(ValueError, match="one-world env on the cpu backend"):
        controller_for(env)
    env.close()


def test_preswap_states_of_another_hand_are_refused():
    with pytest.raises(ValueError, match="states of robot 'shadow', not 'allegro'"):
        reference_env("allegro", seed=0, replay_starts=str(PRESWAP), replay_share=1.0)
