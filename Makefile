# make demo | make test | make bench — each sets up its environment first.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
# make demo installs only what the demo needs (pyproject.toml's user extras vision and viz); make test and the
# other developer targets install the `dev` extra (every user extra, tests, lint, docs, browser, build).
DEMO_EXTRAS := vision,viz
EXTRAS ?= dev
comma := ,
STAMP := $(VENV)/.installed-$(subst $(comma),-,$(EXTRAS))
DEMO_STAMP := $(VENV)/.installed-$(subst $(comma),-,$(DEMO_EXTRAS))

.PHONY: venv demo test lint docs bench bench-env bench-test clean browser train train-base train-refine train-mix train-set

venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[$(EXTRAS)]"
	touch $@

# The demo's environment (a no-op install where `make test` already installed `dev`, which holds vision and viz).
$(DEMO_STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[$(DEMO_EXTRAS)]"
	@# boxtrack's numba kernels (where numba is installed) compiled into numba's cache now, not in the first run
	$(PY) -c "from lookalike.trackers.kernels.boxtrack import warm; warm()"
	touch $@

demo: $(DEMO_STAMP)
	$(VENV)/bin/lookalike demo
	@echo ""
	@echo "The lookalike command is installed in $(VENV)/bin. Run it as"
	@echo "    $(VENV)/bin/lookalike --help"
	@echo "or activate the environment first:  . $(VENV)/bin/activate  && lookalike --help"

test: venv browser docs lint
	$(PY) -m pytest -q

# Static checks (configured in pyproject.toml): ruff, mypy (strict on the core layers) and the import contracts.
lint: venv
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/mypy
	$(VENV)/bin/lint-imports --no-cache

# The documentation site (mkdocs.yml, docs/), built strictly into a temporary folder.
docs: venv
	@out=$$(mktemp -d) && NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet -d "$$out" && rm -rf "$$out" && echo "docs: mkdocs build --strict passed"

# Debian's Chromium for the browser tests; skipped quietly where it cannot be installed
# (the tests then skip with a reason).
browser:
	@command -v chromium >/dev/null 2>&1 || { command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ] && \
		(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) ; } \
		|| echo "chromium not available: browser tests will be skipped"

# The peers need numpy < 2, so benchmarks run in their own environment.
BENCH_VENV := .venv-bench
$(BENCH_VENV)/.installed: pyproject.toml constraints-bench.txt
	$(PYTHON) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(BENCH_VENV)/bin/python -m pip install --quiet -c constraints-bench.txt -e ".[vision,viz,bench,fast,ros]"
	touch $@

# Peers whose declared requirements do not resolve next to numpy < 2 (trackers and boxmot ask numpy >= 2,
# boxmot rich >= 15, the packaged reference SORT pins lap 0.4.0) go in without them; what they import is
# installed beside them (boxmot's motion-only trackers import torch, CPU-only here, PyYAML, tqdm and lap).
BENCH_PEERS_NODEPS := trackers pyDeprecate simple-online-realtime-tracking boxmot
$(BENCH_VENV)/.peers: $(BENCH_VENV)/.installed constraints-bench.txt
	$(BENCH_VENV)/bin/python -m pip install --quiet -c constraints-bench.txt filterpy lap torch pyyaml tqdm pytest
	$(BENCH_VENV)/bin/python -m pip install --quiet --no-deps -c constraints-bench.txt $(BENCH_PEERS_NODEPS)
	touch $@

# The bench environment with every peer; pytest -m bench (the peer adapters, the ranking checks on
# ../shared/data) runs in it.
bench-env: $(BENCH_VENV)/.peers

bench-test: bench-env
	$(BENCH_VENV)/bin/python -m pytest -q -m bench tests/test_bench_real.py tests/test_bench_ranking.py

bench: bench-env
	@log=$$(mktemp); failed=""; \
	for script in benchmarks/[a-z]*.py; do \
		echo "== $$script" | tee -a $$log; \
		$(BENCH_VENV)/bin/python $$script > $$log.one 2>&1 || failed="$$failed $$script"; \
		cat $$log.one; cat $$log.one >> $$log; \
	done; \
	echo "== summary: every TARGET line"; grep '^TARGET' $$log; \
	echo "$$(grep -c '^TARGET.* PASS$$' $$log) PASS, $$(grep -c '^TARGET.* FAIL$$' $$log) FAIL"; \
	rm -f $$log $$log.one; \
	if [ -n "$$failed" ]; then echo "scripts that failed:$$failed"; exit 1; fi

# Reproduce the shipped LSTM weights: a first run per set-up (train-base, 25-40 minutes each on 2
# cores), then refinement with identity-swap augmentation (train-refine): M=3,N=2 and M=5,N=3 on
# this CPU (5-10 minutes per stage); M=10,N=7 for 2,100 steps of 64 sequences, which took 5.5 minutes
# on one H200 with 14 batch workers (--device auto uses a GPU where there is one; a CPU takes hours);
# then a fine-tune on the noise mix (train-mix: ours + paper noise, 15-29 minutes each on one core).
train: train-base train-refine train-mix

train-base: venv
	$(VENV)/bin/lookalike train --preset m3n2 -o runs/m3n2 --steps 3000 --minutes 25 --no-relative
	$(VENV)/bin/lookalike train --preset m5n3 -o runs/m5n3 --steps 8000 --minutes 35 --no-relative
	$(VENV)/bin/lookalike train --preset m10n7 -o runs/m10n7 --steps 8000 --minutes 40

REFINE = $(VENV)/bin/lookalike train --learning-rate 0.002 --patience 40 --steps 1500
train-refine: venv
	$(REFINE) --preset m3n2 --no-relative -o runs/m3n2-refine --init-from runs/m3n2/model.npz --swap-prob 0.3
	$(REFINE) --preset m3n2 --no-relative -o runs/m3n2-refine2 --init-from runs/m3n2-refine/model.npz \
	    --swap-prob 0.5 --learning-rate 0.0015 --seed 1 --ship
	$(REFINE) --preset m5n3 --no-relative -o runs/m5n3-refine --init-from runs/m5n3/model.npz \
	    --swap-prob 0.5 --learning-rate 0.0015 --seed 1 --ship
	$(REFINE) --preset m10n7 -o runs/m10n7-refine --init-from runs/m10n7/model.npz --swap-prob 0.3 \
	    --batch-size 64 --steps 2100 --device auto --workers $$(nproc) --ship

# The noise-mix fine-tunes that ship, each chosen on tuning seeds 50000 by the rule in
# research/notes/robot-identification.md; --steps is the step of the shipped run's best validation
# (those runs stopped on time), so a rerun replays up to it. The shipped JSONs also record the choice.
MIX = OMP_NUM_THREADS=1 $(VENV)/bin/lookalike train --noise mix --patience 40 --threads 1
train-mix: venv
	$(MIX) --preset m3n2 --no-relative -o runs/mix-m3n2 --init-from runs/m3n2-refine2/model.npz \
	    --learning-rate 0.0005 --swap-prob 0.5 --seed 2 --steps 1950 --ship
	$(MIX) --preset m5n3 --no-relative -o runs/mix-m5n3 --init-from runs/m5n3-refine/model.npz \
	    --learning-rate 0.0005 --swap-prob 0.5 --seed 2 --steps 1250 --ship
	$(MIX) --preset m10n7 -o runs/mix-m10n7 --init-from runs/m10n7-refine/model.npz \
	    --learning-rate 0.0002 --batch-size 32 --swap-prob 0.3 --seed 3 --steps 650 --ship

# The 'set' identifier (one network for every team size): 65 minutes of training on one CPU thread, 8 minutes of
# cool-down at a lower learning rate, 67 minutes of fine-tuning towards the paper's small set-ups, then the choice of
# one fine-tuning snapshot on tuning sequences (about 12 minutes); runs stop on time, so a rerun reaches a similar
# step, not the same.
train-set: venv
	OMP_NUM_THREADS=1 $(VENV)/bin/lookalike train --model set -o runs/set --minutes 65
	OMP_NUM_THREADS=1 $(VENV)/bin/lookalike train --model set -o runs/set --resume --minutes 8 --learning-rate 0.0008
	rm -rf runs/set-finetune
	OMP_NUM_THREADS=1 $(PY) research/set/set_finetune.py runs/set-finetune --init runs/set/set.npz --minutes 67
	OMP_NUM_THREADS=1 $(PY) research/set/set_select.py runs/set-finetune --baseline runs/set/set.npz \
	    --average-from 300 --ship

clean:
	rm -rf $(VENV) $(BENCH_VENV) demo-out .pytest_cache
