"""How tests that are not about access get in: a real API token, or the explicit password-less opt-in.

Nothing in the product lets a test past the checks: the helpers below do what a user does, through the product's
own store.

- In-process apps (FastAPI's ``TestClient``): :func:`api_client` creates an API token of the wanted level in the
  app's data directory (as ``servostudio token create`` does) and sends it on every request and WebSocket, and
  adds the test client's host name ``testserver`` to the allowed Host values (``--allowed-host``), since the
  Host check refuses any name that is not this machine's.
- Real servers (``LiveServer``, the browser tests): :func:`passwordless` opts the server's fresh data directory
  into the password-less single-user mode (as ``servostudio setup --passwordless`` does), so every caller on
  this machine is the local administrator, and the unchanged browser UI works. Tests about access start their
  own server with users instead.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from fastapi import FastAPI
from fastapi.testclient import TestClient

from servostudio.api.app import create_app
from servostudio.services.settings import Settings
from servostudio.services.users import Level, UserStore

TEST_HOST = "testserver"  # the Host header of FastAPI's TestClient


def testable(settings: Settings, data_dir: Path) -> Settings:
    """``settings`` with its own data directory and the test client's host name allowed."""
    return dataclasses.replace(settings, data_dir=data_dir, allowed_hosts=(*settings.allowed_hosts, TEST_HOST))


def token(data_dir: Path, level: Level = Level.ADMINISTRATOR) -> str:
    """A fresh API token of ``level`` made in ``data_dir`` (like ``servostudio token create``)."""
    text, _ = UserStore(data_dir).create_token(level, days=1, label="tests")
    return text


def bearer(text: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {text}"}


def api_client(app: FastAPI, level: Level = Level.ADMINISTRATOR, **kwargs) -> TestClient:
    """A test client of ``app`` (built with :func:`testable` settings) that calls with a token of ``level``."""
    text = token(app.state.server.settings.data_dir, level)
    return TestClient(app, headers=bearer(text), **kwargs)


def admin_app(settings: Settings, data_dir: Path) -> FastAPI:
    return create_app(testable(settings, data_dir))


def passwordless(data_dir: Path) -> Path:
    """Opt ``data_dir`` into password-less single-user mode (like ``servostudio setup --passwordless``)."""
    UserStore(data_dir).choose_passwordless()
    return data_dir
