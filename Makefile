# Two commands do all set-up on a fresh machine (Python >= 3.11, Node 20, make):
#   make run   install everything, start the server with simulated drives on http://127.0.0.1:8000
#   make test  install everything, run every test (pytest incl. browser tests, Vitest)

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
HOST ?= 127.0.0.1
PORT ?= 8000
PYTEST_ARGS ?=
FRONTEND_SOURCES := $(shell find frontend/src -type f) frontend/index.html frontend/vite.config.ts frontend/tsconfig.json

.PHONY: run test install install-test frontend chromium test-python test-frontend bench clean

run: install frontend
	$(BIN)/servostudio serve --host $(HOST) --port $(PORT) --projects projects

test: install-test frontend chromium test-frontend test-python

install: $(VENV)/.stamp-install
install-test: $(VENV)/.stamp-install-test

$(VENV)/.stamp-install: pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e .
	touch $@

$(VENV)/.stamp-install-test: $(VENV)/.stamp-install
	$(BIN)/pip install --quiet -e '.[test]'
	touch $@

frontend/node_modules/.stamp: frontend/package.json frontend/package-lock.json
	cd frontend && npm ci --no-audit --no-fund
	touch $@

frontend: backend/servostudio/static/index.html

backend/servostudio/static/index.html: frontend/node_modules/.stamp $(FRONTEND_SOURCES)
	cd frontend && npm run build

# Browser tests drive Debian's Chromium (a test tool's own browser download is not possible here).
chromium:
	@command -v chromium >/dev/null || { \
	  echo "Installing Debian's chromium for the browser tests"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq chromium >/dev/null; }

test-frontend: frontend/node_modules/.stamp
	cd frontend && npm test

test-python: install-test
	$(BIN)/pytest $(PYTEST_ARGS)

bench: install
	@for b in bench/*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) frontend/node_modules backend/servostudio/static
