# make demo : set up .venv (if missing), install joulepath with its extras, run demo.toml -> runs/demo/report.html
#             (the folder of `joulepath run demo` too, so either reuses what the other computed)
# make test : set up .venv (if missing), install joulepath with its extras, build the docs site strictly, run all tests
#             on 2 workers (pytest-xdist, one test file per worker at a time), listing the 15 slowest
# make docs : build the documentation site into build/site (open build/site/index.html)
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test docs bench lint clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(BIN)/python pyproject.toml constraints.txt
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -c constraints.txt -e ".[ml,synth,dask,reference,robots,abb,motion,docs,test]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/joulepath run demo
	@echo "The report: $(CURDIR)/runs/demo/report.html (open it in a browser)"

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks scripts docs
	$(BIN)/mypy src
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir build/site  # no -q: it hides the warnings --strict counts
	$(BIN)/python -m pytest -q -p no:cacheprovider -n 2 --dist loadfile --durations=15

docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir build/site
	@echo "The site: $(CURDIR)/build/site/index.html"

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
	$(BIN)/ruff check src tests benchmarks scripts docs
	$(BIN)/ruff format --check src tests benchmarks scripts docs
	$(BIN)/mypy src

clean:
	rm -rf $(VENV) build *.egg-info
