# make demo | make test | make bench — each sets up .venv first.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
EXTRAS ?= test,vision,viz,train
comma := ,
STAMP := $(VENV)/.installed-$(subst $(comma),-,$(EXTRAS))

.PHONY: venv demo test bench clean browser train train-refine

venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[$(EXTRAS)]"
	touch $@

demo: venv
	$(VENV)/bin/lookalike demo

test: venv browser
	$(PY) -m pytest -q

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
	$(BENCH_VENV)/bin/python -m pip install --quiet -c constraints-bench.txt -e ".[vision,viz,bench]"
	touch $@

bench: $(BENCH_VENV)/.installed
	@for script in benchmarks/[a-z]*.py; do echo "== $$script"; $(BENCH_VENV)/bin/python $$script || exit 1; done

# Reproduce the shipped LSTM weights (about 10-40 minutes per set-up on 2 cores). The shipped
# M=10, N=7 weights then had a second stage (train-refine): 2,100 steps of 64 sequences with identity
# swaps, 5.5 minutes on an H200 with 14 batch workers; on a CPU it is hours, so it is separate.
train: venv
	$(VENV)/bin/lookalike train --preset m3n2 -o runs/m3n2 --steps 3000 --minutes 25 --ship
	$(VENV)/bin/lookalike train --preset m5n3 -o runs/m5n3 --steps 8000 --minutes 35 --ship
	$(VENV)/bin/lookalike train --preset m10n7 -o runs/m10n7 --steps 8000 --minutes 40 --ship

train-refine: venv
	$(VENV)/bin/lookalike train --preset m10n7 -o runs/m10n7-refine --init-from runs/m10n7/model.npz \
	    --batch-size 64 --learning-rate 0.002 --swap-prob 0.3 --patience 40 --steps 2100 \
	    --device auto --workers $$(nproc) --ship

clean:
	rm -rf $(VENV) $(BENCH_VENV) demo-out .pytest_cache
