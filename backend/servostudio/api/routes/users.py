"""The caller's identity as the server sees it (the top bar shows it; user levels build on it)."""

from fastapi import APIRouter
from pydantic import BaseModel, Field

from servostudio.api.deps import Caller

router = APIRouter(tags=["users"])


class UserModel(BaseModel):
    name: str = Field(examples=["local"])
    level: str = Field(examples=["administrator"])


@router.get("/me", response_model=UserModel)
def get_me(user: Caller) -> UserModel:
    return UserModel(name=user.name, level=user.level)
