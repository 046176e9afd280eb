# Two commands set up and check everything: `make generate`, then `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: generate test check lint typecheck clean demo

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test]'
	touch $(STAMP)

generate: $(STAMP)
	$(BIN)/serialspec generate

check: $(STAMP)
	$(BIN)/serialspec check

lint: $(STAMP)
	$(BIN)/ruff check generator generated tests
	$(BIN)/ruff format --check generator tests

typecheck: $(STAMP)
	$(BIN)/mypy generator/serialspec generated

test: $(STAMP) check lint typecheck
	$(BIN)/pytest -q

clean:
	rm -rf $(VENV) build *.egg-info

# A virtual Fashion Star servo on a pseudo-terminal, driven by the generated client: no hardware needed.
demo: $(STAMP)
	$(BIN)/python examples/demo_fashionstar.py
