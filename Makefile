# Entry points for a fresh machine. Everything installs itself through scripts/bootstrap.sh.
VENV ?= .venv
PY := $(VENV)/bin/python
# Demo settings (override on the command line, e.g. make demo ROBOTS=10 VARIANT=gas).
ROBOTS ?= 6
VARIANT ?= gas_sound
SEED ?= 1
OUT ?= runs/demo

.PHONY: bootstrap demo test lint typecheck colcon-check bench clean

bootstrap:
	@scripts/bootstrap.sh

demo: bootstrap
	rm -rf $(OUT)
	$(VENV)/bin/spawn --site small --robots $(ROBOTS) --variant $(VARIANT) --seed $(SEED) \
		--record $(OUT)/bag --out $(OUT)

test: bootstrap
	$(PY) -m pytest -n 2 -q

lint: bootstrap
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# mypy on the ROS-free packages; what it checks and how strictly: [tool.mypy] in pyproject.toml.
typecheck: bootstrap
	$(VENV)/bin/mypy

colcon-check: bootstrap
	scripts/colcon_check.sh

clean:
	rm -rf build install log runs .pytest_cache
