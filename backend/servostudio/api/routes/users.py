"""The caller's identity as the server sees it (the top bar shows it; user levels build on it)."""

from typing import Annotated

from fastapi import APIRouter, Depends
from pydantic import BaseModel, Field

from servostudio.api.deps import User, current_user

router = APIRouter(tags=["users"])


class UserModel(BaseModel):
    name: str = Field(examples=["local"])
    level: str = Field(examples=["administrator"])


@router.get("/me", response_model=UserModel)
def get_me(user: Annotated[User, Depends(current_user)]) -> UserModel:
    return UserModel(name=user.name, level=user.level)
