"""File downloads of the REST API (captures, frequency responses, the commissioning report): one way to name them."""

from __future__ import annotations

from urllib.parse import quote

from fastapi import Response


def attachment(file_name: str) -> dict[str, str]:
    """The download's name, also in RFC 5987 form, so a non-ASCII name (a project's, a capture's) arrives whole."""
    fallback = file_name.encode("ascii", "replace").decode().replace('"', "'")
    return {"Content-Disposition": f"attachment; filename=\"{fallback}\"; filename*=UTF-8''{quote(file_name)}"}


def file_download(body: str, media_type: str, file_name: str) -> Response:
    return Response(body, media_type=media_type, headers=attachment(file_name))
