# Shortcuts; the README's two commands need nothing but Python and pip.
.PHONY: reproduce test bench lint report clean lerobot-check

reproduce:            ## install, then every experiment and the report (dvc re-runs only what changed)
	pip install -e . && python -m dvc repro

test:                 ## install with test tools, then the suite
	pip install -e ".[test]" && python -m pytest

bench:                ## speed of every system and timed algorithm on this machine
	pip install -e ".[bench]" && python -m pipeline.benchmark

report:               ## tables, figures and report again from the runs on disk
	python -m analysis

lerobot-check:        ## the exported datasets loaded by the official lerobot class, in its own venv (it pins torch)
	python -m venv .venv-lerobot && .venv-lerobot/bin/pip install -e ".[test]" "lerobot>=0.4" \
	&& .venv-lerobot/bin/python -m pytest tests/test_dataset.py -k lerobot -rs

lint:
	python -m ruff check .

clean:                ## remove every generated output
	rm -rf data/runs data/metrics data/figures data/report data/datasets data/.hydra
