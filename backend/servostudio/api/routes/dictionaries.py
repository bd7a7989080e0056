"""Object dictionaries of the supported drives: list, browse, import a user EDS."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, UploadFile
from pydantic import BaseModel, Field
from starlette.concurrency import run_in_threadpool

from servostudio.api.deps import Library
from servostudio.api.errors import error_responses
from servostudio.api.limits import MIB, body_limit
from servostudio.api.security import Requires
from servostudio.errors import ErrorKind
from servostudio.od import EdsLibrary, ObjectDictionary, Variable
from servostudio.services import dictionaries
from servostudio.services.users import Level, write_level

router = APIRouter(prefix="/dictionaries", tags=["dictionaries"])
#: an EDS with its properties, as multipart: the largest drive dictionaries are a few hundred kilobytes
EDS_UPLOAD_BYTES = 8 * MIB


class DictionarySummary(BaseModel):
    device: str = Field(examples=["xtrapulspac"])
    product_name: str = Field(examples=["XtrapulsPac"])
    vendor_id: int
    product_code: int
    revision: int
    object_count: int
    builtin: bool


class BitFieldModel(BaseModel):
    first: int
    last: int
    name: str


class EntryModel(BaseModel):
    """One (index, sub) entry with everything an editor needs to show, check and write it."""

    subindex: int
    name: str
    data_type: str = Field(examples=["UNSIGNED16"])
    access: str = Field(examples=["rw"])
    pdo_mappable: bool
    low: int | float | None
    high: int | float | None
    default: int | float | str | None = Field(
        description="DefaultValue; a default that depends on the node ID stays the EDS expression ('$NODEID+0x180')"
    )
    default_node_offset: int | None = Field(
        None, description="for a '$NODEID' default: the value for node n is n + this offset; null otherwise"
    )
    configured: int | float | str | None = Field(
        None, description="a DCF's ParameterValue (the value commissioning configured), '$NODEID' kept as default"
    )
    configured_node_offset: int | None = Field(
        None, description="for a '$NODEID' ParameterValue: the configured value for node n is n + this offset"
    )
    unit: str
    scale: float
    offset: float
    save_type: str = Field(examples=["DRIVEPAR"])
    group: str
    description: str
    enum: dict[str, str]
    bits: list[BitFieldModel]
    is_pointer: bool
    reference: str
    write_level: Level | None = Field(
        description="the lowest user level that may write it (null: nobody, read-only); docs/security.md"
    )


class ObjectModel(BaseModel):
    index: int
    name: str
    kind: str = Field(examples=["VAR", "ARRAY", "RECORD"])
    group: str
    subs: list[EntryModel]


class DictionaryModel(DictionarySummary):
    groups: list[str]
    objects: list[ObjectModel]
    names: dict[str, tuple[int, int]] = Field(
        description="the device profile's semantic names (statusword, position_actual, …) that this dictionary has "
        "→ [index, sub]: how a client finds this device's entries by meaning"
    )
    fieldbus: str = Field(examples=["CANopen", "PROFIBUS-DP"])
    files: list[str] = Field(
        description="the drive's own files a backup of this device holds, in the order a restore writes them",
        examples=[["DRIVEPAR.TXT", "USER_PAR.TXT", "SEQUENCE.TXT"], ["TTAPAR.TXT", "TTASEQ.TXT"]],
    )
    features: list[str] = Field(
        description="the services the device has, of scope, current_loop, phasing, auto_tuning, frequency_response, "
        "sequences, io: what a client offers it (the server refuses the others)",
        examples=[["scope", "current_loop", "phasing", "auto_tuning", "frequency_response", "sequences", "io"], []],
    )
    store: str | None = Field(
        description="what storing the parameters (POST …/store) writes on this device, in its dictionary's words",
        examples=["0x1010,1 Store parameters.Save all parameters = 'save'", "PNU 729 Save parameters in EEPROM = 1"],
    )


def _summary(library: EdsLibrary, od: ObjectDictionary) -> dict:
    return {
        "device": od.device,
        "product_name": od.product_name,
        "vendor_id": od.vendor_id,
        "product_code": od.product_code,
        "revision": od.revision,
        "object_count": len(od.objects()),
        "builtin": dictionaries.is_builtin(library, od.device),
    }


def _shown(value: object, expression: str | None, node_offset: int | None) -> int | float | str | None:
    """A dictionary value as the API shows it without a node: a '$NODEID' value as its expression (the number
    depends on the node, given by the ``*_node_offset`` field), bytes as hex."""
    if node_offset is not None:
        return expression
    if isinstance(value, bytes):
        return value.hex()
    return value if isinstance(value, (int, float, str)) else None


def _entry(var: Variable) -> EntryModel:
    return EntryModel(
        subindex=var.subindex,
        name=var.name,
        data_type=var.data_type.name,
        access=var.access.value,
        pdo_mappable=var.pdo_mappable,
        low=var.low,
        high=var.high,
        default=_shown(var.default, var.default_expr, var.default_node_offset),
        default_node_offset=var.default_node_offset,
        configured=_shown(var.parameter_value, var.parameter_expr, var.parameter_node_offset),
        configured_node_offset=var.parameter_node_offset,
        unit=var.unit,
        scale=var.scale,
        offset=var.offset,
        save_type=var.save_type.value,
        group=var.group,
        description=var.description,
        enum={str(value): text for value, text in var.enum.items()},
        bits=[BitFieldModel(first=b.first, last=b.last, name=b.name) for b in var.bits],
        is_pointer=var.is_pointer,
        reference=var.reference,
        write_level=write_level(var),
    )


@router.get("", response_model=list[DictionarySummary], dependencies=[Requires(Level.OPERATOR)])
def list_dictionaries(library: Library) -> list[dict]:
    return [_summary(library, library.load(device)) for device in library.devices()]


@router.get(
    "/{device}",
    response_model=DictionaryModel,
    responses=error_responses(ErrorKind.NOT_FOUND),
    dependencies=[Requires(Level.OPERATOR)],
)
def get_dictionary(device: str, library: Library) -> DictionaryModel:
    od = dictionaries.dictionary(library, device)
    objects = [
        ObjectModel(
            index=obj.index,
            name=obj.name,
            kind=obj.kind.value,
            group=obj.group,
            subs=[_entry(var) for _, var in sorted(obj.subs.items())],
        )
        for obj in od.objects()
    ]
    groups = list(dict.fromkeys(obj.group for obj in od.objects() if obj.group))
    return DictionaryModel(
        **_summary(library, od),
        groups=groups,
        objects=objects,
        names=dictionaries.profile_names(od),
        fieldbus=dictionaries.fieldbus(od),
        files=dictionaries.drive_files(od),
        features=dictionaries.features(od),
        store=dictionaries.store_action(od),
    )


@router.post(
    "",
    response_model=DictionarySummary,
    status_code=201,
    responses=error_responses(ErrorKind.TOO_LARGE),
    openapi_extra=body_limit(EDS_UPLOAD_BYTES),
    dependencies=[Requires(Level.ADMINISTRATOR)],
)
async def import_dictionary(
    library: Library,
    eds: Annotated[UploadFile, File(description="CiA 306 EDS file")],
    props: Annotated[UploadFile | None, File(description="companion .props file")] = None,
) -> dict:
    """Validate an EDS (and its companion properties) and add it to the user library; nothing is kept on error."""
    props_bytes = await props.read() if props is not None else None
    device = await run_in_threadpool(
        dictionaries.import_upload, library, eds.filename or "upload.eds", await eds.read(), props_bytes
    )
    return _summary(library, library.load(device))
