# make demo : set up .venv (if missing), install joulepath with its extras, run demo.toml -> runs/demo/report.html
#             (the folder of `joulepath run demo` too, so either reuses what the other computed)
# make test : set up .venv (if missing), install joulepath with its extras, run all tests
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench lint clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(BIN)/python pyproject.toml constraints.txt
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -c constraints.txt -e ".[ml,synth,dask,reference,robots,abb,motion,test]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/joulepath run demo
	@echo "The report: $(CURDIR)/runs/demo/report.html (open it in a browser)"

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks scripts
	$(BIN)/mypy src
	$(BIN)/python -m pytest -q -p no:cacheprovider

bench: $(STAMP)
	$(BIN)/python benchmarks/dynamics.py
	$(BIN)/python benchmarks/data.py
	$(BIN)/python benchmarks/evolve.py
	$(BIN)/python benchmarks/learn.py
	$(BIN)/python benchmarks/optimizers.py
	$(BIN)/python benchmarks/synth.py
	$(BIN)/python benchmarks/experiment.py
	$(BIN)/python benchmarks/egm.py

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks scripts
	$(BIN)/ruff format --check src tests benchmarks scripts
	$(BIN)/mypy src

clean:
	rm -rf $(VENV) build *.egg-info
