# roto: `make train` and `make test` bootstrap .venv on first use.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: train test lint bench clean

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/python -m pip install --quiet torch==2.13.0
	$(VENV)/bin/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

# Until the trainer lands, `make train` runs the scripted Bounce policy on 8 envs (a short demo).
train: $(STAMP)
	$(VENV)/bin/roto demo --task bounce --robot shadow --num_envs 8 --episodes 1

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check . && $(VENV)/bin/ruff format --check .

bench: $(STAMP)
	$(VENV)/bin/roto bench --task bounce --num_envs 256 --threads 1 --json
	$(VENV)/bin/roto bench --task baoding --num_envs 256 --threads 1 --json

clean:
	rm -rf $(VENV) *.egg-info
