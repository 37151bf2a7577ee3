"""The Baoding reference controller: it swaps from the pre-swap states it recorded, and refuses
envs it cannot plan for."""

import pathlib

import numpy as np
import pytest

from roto.reference.baoding_controller import (
    BaodingReference,
    load_preswap_states,
    reference_env,
    restore_preswap_state,
)
from roto.reference.baoding_cost import BaodingCostWeights
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig
from roto.registry import make

RESULTS = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "baoding_reference"


def controller_for(env, seed: int = 0) -> BaodingReference:
    lo, hi = env._idx.ctrl_lo.numpy(), env._idx.ctrl_hi.numpy()
    planner = PredictiveSampling(env.model, lo, hi, SamplingConfig(threads=1, seed=seed))
    return BaodingReference(env, planner, BaodingCostWeights())


@pytest.mark.parametrize("k", [0, 5])
def test_from_a_recorded_preswap_state_the_controller_swaps_again(k):
    """The recorded states fit the Shadow's scene and lead to a swap within a few tenths of a second
    (recorded 10 control steps before one), with a planner seeded afresh."""
    states = load_preswap_states(RESULTS / "shadow_preswap.npz")
    assert int(states["lead_steps"]) == 10 and len(states["physics"]) >= 100
    env = reference_env("shadow", seed=0)
    env.reset()
    controller = controller_for(env)
    restore_preswap_state(env, states, k)
    np.testing.assert_array_equal(env.backend.physics_state()[0], states["physics"][k])
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
    states = load_preswap_states(RESULTS / "shadow_preswap.npz")
    env = reference_env("allegro", seed=0)
    with pytest.raises(ValueError, match="pre-swap states of robot 'shadow' do not fit an env of 'allegro'"):
        restore_preswap_state(env, states, 0)
    env.close()
