"""The API contract is true: schemathesis generates requests from the OpenAPI schema for every operation and checks
each answer — no 5xx, a body that fits the schema of its status, no status or content type the operation does not
declare.

Bounded for ``make test``: a fixed seed (``derandomize``), a few examples per operation and pass, against the app in
this process (``from_asgi``) with the embedded simulated drives and an administrator's API token
(`tests.support.access`). Up to three passes per operation: valid requests, invalid ones (negative data, for the
operations with a body), and valid ones whose path names what exists — the simulated bus and drive, a project
with an axis — so the routes also answer from their success paths, not only with "not found".
"""

from __future__ import annotations

import pytest
import schemathesis
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis.errors import Unsatisfiable
from schemathesis import GenerationMode, checks
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

#: Operations not run, each with its reason: none may move a motor, take minutes, or remove what the others test.
SKIPPED = {
    "PUT /api/buses/{bus}/nodes/{node}/state": "walks the CiA 402 state machine of a drive: it may enable an axis",
    "POST /api/projects/{name}/commission": "downloads a whole project into the drives (a job of minutes on real ones)",
    "DELETE /api/buses/{bus}": "closing the one simulated bus would leave nothing for the drive operations to test",
}
CHECKS = [
    checks.not_a_server_error,
    checks.status_code_conformance,
    checks.response_schema_conformance,
    checks.content_type_conformance,
]
EXAMPLES = 5
PROJECT, AXIS = "demo", "X"
#: path parameters naming what exists (``name`` is a project's, but a drive file's in ``…/files/{name}``)
EXISTING = {
    "bus": "sim",
    "node": 1,
    "key": "statusword",
    "device": "xtrapulspac",
    "name": PROJECT,
    "axis": AXIS,
    "address": "0x6065",
}


@pytest.fixture(scope="module")
def contract_app(tmp_path_factory):
    root = tmp_path_factory.mktemp("contract")
    app = admin_app(
        Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",), export_dir=root / "exp"),
        root / "data",
    )
    with api_client(app) as client:  # the lifespan: the simulated bus is open while schemathesis calls
        assert client.post("/api/buses/sim/scan").status_code == 200
        project = {"name": PROJECT, "buses": [{"name": "sim", "interface": "sim"}]}
        assert client.post("/api/projects", json=project).status_code == 201
        axis = {"name": AXIS, "device": "xtrapulspac", "node_id": 1, "bus": "sim"}
        assert client.post(f"/api/projects/{PROJECT}/axes", json=axis).status_code == 201
        app.state.contract_headers = dict(client.headers)
        yield app


def _existing(operation) -> dict[str, object]:
    names = {parameter.name for parameter in operation.iter_parameters() if parameter.location == "path"}
    known = {name: value for name, value in EXISTING.items() if name in names}
    if "/files/" in operation.path:
        known["name"] = "USER_PAR.TXT"
    return known


def _strategies(operation):
    """The passes of one operation: (what it is called, its strategy). Invalid requests are made of invalid bodies:
    a path of text parameters has hardly any invalid value (and looking for one costs seconds)."""
    modes = (GenerationMode.POSITIVE, GenerationMode.NEGATIVE) if len(operation.body) else (GenerationMode.POSITIVE,)
    passes = [(mode.value, operation.as_strategy(mode)) for mode in modes]
    known = _existing(operation)
    if known:
        passes.append(("existing", operation.as_strategy(GenerationMode.POSITIVE, path_parameters=known)))
    return passes


def _exercise(label: str, strategy, headers: dict[str, str]) -> str | None:
    """Run the examples of one pass; what failed, or None."""

    @given(strategy)
    @settings(
        max_examples=EXAMPLES,
        derandomize=True,
        deadline=None,
        suppress_health_check=list(HealthCheck),
        database=None,
        phases=[Phase.explicit, Phase.generate],
    )
    def run(case) -> None:
        case.call_and_validate(headers=headers, checks=CHECKS)

    try:
        run()
    except Unsatisfiable:  # nothing to make invalid: an operation without parameters has no negative case
        return None
    except (Exception, BaseExceptionGroup) as failure:  # noqa: BLE001 -- every operation is tried, all failures shown
        return f"{label}: {failure}"
    return None


def test_every_operation_keeps_its_contract(contract_app):
    schema = schemathesis.openapi.from_asgi("/openapi.json", contract_app)
    operations = [result.ok() for result in schema.get_all_operations()]
    tried = [operation for operation in operations if operation.label not in SKIPPED]
    assert len(tried) == len(operations) - len(SKIPPED)  # every skip names an operation that exists
    headers = contract_app.state.contract_headers
    failures = [
        failure
        for operation in tried
        for name, strategy in _strategies(operation)
        if (failure := _exercise(f"{operation.label} ({name})", strategy, headers)) is not None
    ]
    assert not failures, "\n\n".join(failures)


def test_the_client_of_the_contract_run_gets_in(contract_app):
    """The run is worth something only if its calls pass the access checks."""
    with TestClient(contract_app, headers=contract_app.state.contract_headers) as client:
        assert client.get("/api/buses/sim/nodes/1/objects/statusword").status_code == 200
