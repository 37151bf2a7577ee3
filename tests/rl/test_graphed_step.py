"""The update's speed-ups: ``ppo.cuda_graph`` (the graphed update trains as the eager one does, on a
GPU; a setting it cannot run is refused before any training, everywhere), ``ppo.fused_adam``
(the same update as PyTorch's default Adam, on the CPU and graphed on a GPU) and
``ppo.bf16_update`` (the update's products in bfloat16, its steps pointing where FP32's do) and
``ppo.compile_update`` (the forward pass and losses compiled, training as the eager ones)."""

import pytest
import torch

from roto.rl.build import build_learner, build_model
from roto.rl.config_files import load_agent_config
from roto.rl.graphed_call import clone_tree, copy_tree

SIZES = {"proprio": 12, "tactile": 4}
NUM_ACTIONS = 3
NUM_ENVS = 64
needs_cuda = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs an NVIDIA GPU")


def learner(device, overrides):
    agent = load_agent_config("bounce", overrides=["ppo.rollouts=4", "ppo.epochs=3", "ppo.minibatches=4", *overrides])
    torch.manual_seed(0)
    model = build_model(SIZES, NUM_ACTIONS, agent, "blind").to(device)
    return build_learner(model, SIZES, NUM_ACTIONS, NUM_ENVS, agent, seed=0, touch="binary")


def fill(alg, device, seed):
    """One rollout of made-up observations and rewards, then the returns."""
    data = torch.Generator(device="cpu").manual_seed(seed)
    for _ in range(alg.storage.steps):
        obs = {g: torch.randn(NUM_ENVS, d, generator=data).to(device) for g, d in SIZES.items()}
        alg.act(obs)
        reward = torch.randn(NUM_ENVS, generator=data).to(device)
        done = (torch.rand(NUM_ENVS, generator=data) < 0.1).to(device)
        alg.process_step(reward, done, torch.zeros_like(done), {})
    alg.compute_returns({g: torch.randn(NUM_ENVS, d, generator=data).to(device) for g, d in SIZES.items()})


def assert_trains_alike(reference, other, device, rel, abs_, updates=3):
    """Both learners, fed the same rollouts, report the same metrics and hold the same weights after
    every update (within rel/abs_)."""
    for seed in range(updates):
        fill(reference, device, seed)
        fill(other, device, seed)
        reference_out, other_out = reference.update(), other.update()
        for name, value in reference_out.items():
            assert other_out[name] == pytest.approx(value, rel=rel, abs=abs_), name
        for a, b in zip(reference.model.parameters(), other.model.parameters(), strict=True):
            torch.testing.assert_close(b, a, rtol=rel, atol=abs_)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ([], "needs the envs on a CUDA device, got device='cpu'"),
        (["ppo.minibatches=3"], "ppo.rollouts x num_envs = 256 is not divisible by ppo.minibatches=3"),
        (["ssl.forward_dynamics={seq_length: 2}"], "does not graph auxiliary losses yet; set it false or drop ssl"),
        (["ppo.bf16_update=true"], "does not graph the bfloat16 update yet; set ppo.bf16_update=false"),
    ],
)
def test_a_setting_the_graph_cannot_run_is_refused_naming_it(overrides, message):
    with pytest.raises(ValueError, match=r"ppo\.cuda_graph=true") as error:
        learner(torch.device("cpu"), ["ppo.cuda_graph=true", *overrides])
    assert message in str(error.value)


def test_inputs_are_copied_in_place_and_a_changed_shape_is_refused():
    batch = {"obs": {"proprio": torch.ones(4, 2)}, "actions": torch.zeros(4, 1)}
    inputs = clone_tree(batch)
    address = inputs["obs"]["proprio"].data_ptr()
    copy_tree(inputs, {"obs": {"proprio": torch.full((4, 2), 7.0)}, "actions": torch.ones(4, 1)})
    assert inputs["obs"]["proprio"].data_ptr() == address and inputs["obs"]["proprio"].eq(7).all()
    assert batch["obs"]["proprio"].eq(1).all()  # the clone owns its storage
    with pytest.raises(ValueError, match=r"changed shape: \(4, 1\) -> \(3, 1\)"):
        copy_tree(inputs, {"obs": {"proprio": torch.ones(4, 2)}, "actions": torch.ones(3, 1)})


def test_fused_adam_trains_as_the_default_adam():
    device = torch.device("cpu")
    plain, fused = learner(device, ["ppo.lr=1e-3"]), learner(device, ["ppo.lr=1e-3", "ppo.fused_adam=true"])
    assert fused.optimizer.defaults["fused"] and not plain.optimizer.defaults["fused"]
    start = [p.detach().clone() for p in plain.model.parameters()]
    assert_trains_alike(plain, fused, device, rel=1e-4, abs_=1e-6)
    moved = [not torch.equal(p, q) for p, q in zip(plain.model.parameters(), start, strict=True)]
    assert sum(moved) > len(moved) // 2  # the updates trained: equal weights are not two idle optimisers


@pytest.mark.gpu
@needs_cuda
@pytest.mark.parametrize(("kl_adaptive", "fused"), [(False, False), (True, False), (True, True)])
def test_graphed_updates_train_as_eager_ones(kl_adaptive, fused):
    device = torch.device("cuda")
    flags = [f"ppo.kl_adaptive={str(kl_adaptive).lower()}", "ppo.lr=1e-3", "ppo.cuda_graph=true"]
    flags.append(f"ppo.fused_adam={str(fused).lower()}")
    eager, graphed = learner(device, flags), learner(device, flags)
    eager._graphed = None  # the same capturable Adam and lr tensor, stepped eagerly: the reference
    assert_trains_alike(eager, graphed, device, rel=1e-5, abs_=1e-7)  # the first update captures
    assert graphed.lr == pytest.approx(eager.lr)


def test_a_compiled_update_trains_as_the_eager_one():
    """``ppo.compile_update``: the forward pass and loss terms run as TorchInductor's fused kernels
    (the function really is compiled) and train the weights as the eager ones do."""
    device = torch.device("cpu")
    flags = ["ppo.lr=1e-3", "ppo.kl_adaptive=true"]
    eager, compiled = learner(device, flags), learner(device, [*flags, "ppo.compile_update=true"])
    assert eager._ppo_loss == eager._ppo_terms and compiled._ppo_loss != compiled._ppo_terms
    # Adam divides by the gradients' running scale: where a gradient is near zero, rounding apart
    # moves a weight by up to 5e-6 (of steps of 1e-3) after three updates
    assert_trains_alike(eager, compiled, device, rel=1e-4, abs_=2e-5)
    assert compiled.lr == pytest.approx(eager.lr)


@pytest.mark.gpu
@needs_cuda
def test_a_compiled_update_replayed_from_a_graph_trains_as_the_eager_one():
    device = torch.device("cuda")
    flags = ["ppo.lr=1e-3", "ppo.kl_adaptive=true", "ppo.cuda_graph=true", "ppo.fused_adam=true"]
    eager, compiled = learner(device, flags), learner(device, [*flags, "ppo.compile_update=true"])
    eager._graphed = None
    assert_trains_alike(eager, compiled, device, rel=1e-4, abs_=2e-5)


@pytest.mark.gpu
@needs_cuda
def test_graphed_minibatch_steps_never_wait_for_the_device():
    device = torch.device("cuda")
    alg = learner(device, ["ppo.cuda_graph=true"])
    fill(alg, device, 0)
    alg.update()  # captures
    fill(alg, device, 1)
    batches = list(alg.storage.minibatches(alg.config.minibatches, alg.generator))
    torch.cuda.set_sync_debug_mode("error")
    try:
        for batch in batches:
            alg._graphed(batch)
    finally:
        torch.cuda.set_sync_debug_mode(0)
    assert all(torch.isfinite(p).all() for p in alg.model.parameters())


@pytest.mark.parametrize("enabled", [False, True])
def test_tf32_update_allows_tf32_only_during_the_update(enabled, monkeypatch):
    alg = learner(torch.device("cpu"), [f"ppo.tf32_update={str(enabled).lower()}"])
    seen, step = [], alg._minibatch_step

    def recording_step(*args):
        seen.append(torch.backends.cuda.matmul.allow_tf32)
        return step(*args)

    monkeypatch.setattr(alg, "_minibatch_step", recording_step)
    fill(alg, torch.device("cpu"), 0)
    assert not torch.backends.cuda.matmul.allow_tf32
    alg.update()
    assert seen and set(seen) == {enabled}
    assert not torch.backends.cuda.matmul.allow_tf32  # restored after the update


def test_bf16_update_runs_the_update_in_bfloat16_and_keeps_the_rest_fp32():
    device = torch.device("cpu")
    alg = learner(device, ["ppo.bf16_update=true"])
    first_linear = next(m for m in alg.model.modules() if isinstance(m, torch.nn.Linear))
    seen = []
    first_linear.register_forward_hook(lambda module, inputs, output: seen.append(output.dtype))
    fill(alg, device, seed=0)
    assert set(seen) == {torch.float32}  # the rollout's inference is untouched
    seen.clear()
    obs = alg.storage.flat_obs()
    metrics = alg.update()
    assert set(seen) == {torch.bfloat16}
    assert all(p.dtype == torch.float32 for p in alg.model.parameters())
    assert all(torch.isfinite(torch.tensor(value)) for value in metrics.values())
    assert all(out.dtype == torch.float32 for out in alg._forward(obs))  # the losses see FP32


def test_bf16_update_scores_the_old_policy_with_its_own_forward():
    """With a narrow policy (std e^-3) and large means, FP32 log-probs of the rollout against bfloat16
    ones of the update would put ratios outside the clip before any step; rescored, a step of lr 0
    leaves every ratio at 1 (an lr of 1e-12: the weights stay put)."""
    device = torch.device("cpu")
    alg = learner(device, ["ppo.bf16_update=true", "ppo.lr=1e-12", "ppo.ratio_clip=0.1"])
    with torch.no_grad():
        alg.model.log_std.fill_(-3.0)
        alg.model.policy_mean.weight.mul_(50.0)
    fill(alg, device, seed=0)
    metrics = alg.update()
    assert metrics["ppo/clip_fraction"] == 0.0
    assert abs(metrics["ppo/approx_kl"]) < 1e-4  # 1.3e-5 when written (minibatch-sized products round apart)


def test_bf16_update_moves_the_weights_as_the_fp32_update_does():
    """Same start, same rollouts: the bf16 update's weight change points where the FP32 one does,
    without being the same change (the products really ran in bfloat16)."""
    device = torch.device("cpu")
    fp32, bf16 = learner(device, ["ppo.lr=1e-4"]), learner(device, ["ppo.lr=1e-4", "ppo.bf16_update=true"])
    start = torch.nn.utils.parameters_to_vector(fp32.model.parameters()).detach().clone()
    for seed in range(2):
        fill(fp32, device, seed)
        fill(bf16, device, seed)
        fp32.update(), bf16.update()
    step_fp32 = torch.nn.utils.parameters_to_vector(fp32.model.parameters()).detach() - start
    step_bf16 = torch.nn.utils.parameters_to_vector(bf16.model.parameters()).detach() - start
    cosine = torch.nn.functional.cosine_similarity(step_fp32, step_bf16, dim=0)
    assert cosine > 0.99  # 0.9989 when written
    assert not torch.allclose(step_fp32, step_bf16, rtol=1e-4, atol=1e-7)


def test_a_graphed_rollout_off_a_gpu_is_refused_naming_it():
    message = r"ppo\.cuda_graph_rollout=true needs the envs on a CUDA device, got device='cpu'"
    with pytest.raises(ValueError, match=message):
        learner(torch.device("cpu"), ["ppo.cuda_graph_rollout=true"])


def test_an_action_is_the_policy_mean_plus_its_std_times_the_generators_next_normal_draw():
    """The rollout's draw (eager here, the same function graphed on a GPU): noise from the learner's
    generator, drawn before the policy pass, so a run's actions are what they were before."""
    alg = learner(torch.device("cpu"), [])
    obs = {g: torch.randn(NUM_ENVS, d) for g, d in SIZES.items()}
    expected_noise = torch.randn((NUM_ENVS, NUM_ACTIONS), generator=alg.generator.clone_state())
    action = alg.act(obs)
    with torch.no_grad():
        mean, log_std, _, _ = alg.model(obs)
    torch.testing.assert_close(action, mean + log_std.exp() * expected_noise)
    assert alg._step["log_prob"].shape == (NUM_ENVS,) and alg._step["value"].shape == (NUM_ENVS,)


@pytest.mark.gpu
@needs_cuda
def test_graphed_rollouts_act_and_train_as_eager_ones():
    """The same generator draws, the same actions, log-probabilities and values, step after step and
    after updates change the weights and statistics the graph reads in place; no host sync."""
    device = torch.device("cuda")
    eager, graphed = learner(device, []), learner(device, ["ppo.cuda_graph_rollout=true"])
    for seed in range(3):
        data = torch.Generator(device="cpu").manual_seed(seed)
        for step in range(eager.storage.steps):
            obs = {g: torch.randn(NUM_ENVS, d, generator=data).to(device) for g, d in SIZES.items()}
            if seed or step:  # the first call captures (allocations are allowed there)
                torch.cuda.set_sync_debug_mode("error")
            try:
                graphed_action = graphed.act(obs)
            finally:
                torch.cuda.set_sync_debug_mode(0)
            # the two learners' updates agree to rounding (test_graphed_updates_train_as_eager_ones)
            torch.testing.assert_close(graphed_action, eager.act(obs), rtol=1e-4, atol=1e-5)
            for key in ("log_prob", "value"):
                torch.testing.assert_close(graphed._step[key], eager._step[key], rtol=1e-4, atol=1e-4)
            reward = torch.randn(NUM_ENVS, generator=data).to(device)
            done = (torch.rand(NUM_ENVS, generator=data) < 0.1).to(device)
            for alg in (eager, graphed):
                alg.process_step(reward, done, torch.zeros_like(done), {})
        last = {g: torch.randn(NUM_ENVS, d, generator=data).to(device) for g, d in SIZES.items()}
        for alg in (eager, graphed):
            alg.compute_returns(last)
            alg.update()
