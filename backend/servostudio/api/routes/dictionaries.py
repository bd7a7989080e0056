"""Object dictionaries of the supported drives: list, browse, import a user EDS."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Annotated

from fastapi import APIRouter, Depends, File, HTTPException, UploadFile
from pydantic import BaseModel, Field

from servostudio.api.deps import User, current_user, eds_library
from servostudio.od import DictionaryError, EdsLibrary, LibraryError, ObjectDictionary, Variable

router = APIRouter(prefix="/dictionaries", tags=["dictionaries"])

Library = Annotated[EdsLibrary, Depends(eds_library)]
Caller = Annotated[User, Depends(current_user)]


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
    default: int | float | str | None
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


class ObjectModel(BaseModel):
    index: int
    name: str
    kind: str = Field(examples=["VAR", "ARRAY", "RECORD"])
    group: str
    subs: list[EntryModel]


class DictionaryModel(DictionarySummary):
    groups: list[str]
    objects: list[ObjectModel]


def _summary(library: EdsLibrary, od: ObjectDictionary) -> dict:
    return {
        "device": od.device,
        "product_name": od.product_name,
        "vendor_id": od.vendor_id,
        "product_code": od.product_code,
        "revision": od.revision,
        "object_count": len(od.objects()),
        "builtin": library.path_of(od.device).parent == library.builtin_dir,
    }


def _entry(var: Variable) -> EntryModel:
    default = var.default.hex() if isinstance(var.default, bytes) else var.default
    return EntryModel(
        subindex=var.subindex,
        name=var.name,
        data_type=var.data_type.name,
        access=var.access.value,
        pdo_mappable=var.pdo_mappable,
        low=var.low,
        high=var.high,
        default=default,
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
    )


def _load(library: EdsLibrary, device: str) -> ObjectDictionary:
    try:
        return library.load(device)
    except LibraryError as error:
        raise HTTPException(status_code=404, detail=str(error)) from error


@router.get("", response_model=list[DictionarySummary])
def list_dictionaries(library: Library, _: Caller) -> list[dict]:
    return [_summary(library, library.load(device)) for device in library.devices()]


@router.get("/{device}", response_model=DictionaryModel)
def get_dictionary(device: str, library: Library, _: Caller) -> DictionaryModel:
    od = _load(library, device)
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
    return DictionaryModel(**_summary(library, od), groups=groups, objects=objects)


@router.post("", response_model=DictionarySummary, status_code=201)
async def import_dictionary(
    library: Library,
    _: Caller,
    eds: Annotated[UploadFile, File(description="CiA 306 EDS file")],
    props: Annotated[UploadFile | None, File(description="companion .props file")] = None,
) -> dict:
    """Validate an EDS (and its companion properties) and add it to the user library; nothing is kept on error."""
    with tempfile.TemporaryDirectory() as staging:
        eds_path = Path(staging) / Path(eds.filename or "upload.eds").name
        eds_path.write_bytes(await eds.read())
        props_path = None
        if props is not None:
            props_path = eds_path.with_suffix(".props")
            props_path.write_bytes(await props.read())
        try:
            device = library.import_eds(eds_path, props_path)
        except (DictionaryError, LibraryError) as error:
            # Name the file as the user uploaded it, not as it was staged on the server.
            detail = str(error).replace(f"{staging}{os.sep}", "")
            raise HTTPException(status_code=422, detail=detail) from error
    return _summary(library, library.load(device))
