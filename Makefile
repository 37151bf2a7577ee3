# roto: `make train` and `make test` bootstrap .venv on first use.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test-extras

.PHONY: train test lint bench clean

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/python -m pip install --quiet torch==2.13.0
	$(VENV)/bin/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

# the tests also cover the Warp backend on Warp's CPU device, the learner adapters and sweeps on
# PostgreSQL and W&B logging, so they need the gpu, sb3, rsl_rl, skrl, postgres and wandb extras
$(TEST_STAMP): $(STAMP)
	$(VENV)/bin/python -m pip install --quiet -e '.[dev,gpu,sb3,rsl_rl,skrl,postgres,wandb]'
	touch $(TEST_STAMP)

# The quick start: a blind Shadow Bounce agent on the CPU (about 15 minutes on 2 cores);
# `make train SEED=1` trains another seed.
SEED ?= 0
train: $(STAMP)
	$(VENV)/bin/roto train --task bounce --robot shadow --obs blind --num_envs 128 --threads 2 \
		--torch_threads 2 --steps 2500000 --seed $(SEED) --agent_cfg roto/configs/bounce_cpu_quickstart.yaml

# ROTO_REQUIRE_WARP / ROTO_REQUIRE_EXTRAS: a missing MuJoCo Warp or learner library fails its
# tests instead of skipping them
test: $(TEST_STAMP)
	ROTO_REQUIRE_WARP=1 ROTO_REQUIRE_EXTRAS=1 $(VENV)/bin/python -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check . && $(VENV)/bin/ruff format --check .

bench: $(STAMP)
	$(VENV)/bin/roto bench --task bounce --num_envs 256 --threads 1 --json
	$(VENV)/bin/roto bench --task baoding --num_envs 256 --threads 1 --json

clean:
	rm -rf $(VENV) *.egg-info
