"""`create_app` builds the server's whole state once, from its settings; the lifespan opens and closes the buses."""

from __future__ import annotations

from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings, create_app
from servostudio.api.state import ServerState


def test_the_state_is_built_from_the_settings(tmp_path):
    settings = Settings(
        projects_dir=tmp_path / "projects",
        user_eds_dir=tmp_path / "user-eds",
        motors_dir=tmp_path / "motors",
        static_dir=tmp_path / "no-ui",
    )
    state = create_app(settings).state.server
    assert isinstance(state, ServerState) and state.settings is settings
    assert state.library.user_dir == tmp_path / "user-eds"
    assert state.connections.library is state.library and state.jobs.events is state.events
    assert state.projects.store.root == tmp_path / "projects"
    assert state.projects.motors.builtin_dir == tmp_path / "motors"


def test_the_lifespan_opens_the_settings_buses_and_closes_them(tmp_path):
    app = admin_app(Settings(projects_dir=tmp_path, static_dir=tmp_path / "no-ui", buses=("sim",)), tmp_path / "data")
    connections = app.state.server.connections
    assert connections.list() == []
    with api_client(app) as client:
        assert [bus["id"] for bus in client.get("/api/buses").json()] == ["sim"]
    assert connections.list() == []
