"""Who is calling, logging in and out, the first start's setup, users and API tokens (``docs/security.md``)."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response, status
from pydantic import BaseModel, Field

from servostudio.api.auth import SESSION_COOKIE, clear_session_cookies, is_tls, set_session_cookies
from servostudio.api.deps import Access, Caller
from servostudio.api.errors import error_responses
from servostudio.api.security import Anyone, Requires
from servostudio.errors import ErrorKind, InvalidInput
from servostudio.services.users import TOKEN_DAYS_DEFAULT, ApiToken, Level, Session, User
from servostudio.services.users.store import TOKEN_DAYS_MAX, Account

router = APIRouter(
    tags=["users"],
    responses=error_responses(ErrorKind.UNAUTHENTICATED, ErrorKind.FORBIDDEN, ErrorKind.NOT_FOUND),
)
LOGIN_ERRORS = error_responses(ErrorKind.RATE_LIMITED, ErrorKind.CONFLICT)
ADMINISTRATOR = [Requires(Level.ADMINISTRATOR)]
ANY_USER = [Requires(Level.OPERATOR)]


class UserModel(BaseModel):
    name: str = Field(examples=["local"])
    level: Level = Field(examples=["administrator"])


class AccountModel(UserModel):
    created: float = Field(description="seconds since the epoch")


class Login(BaseModel):
    name: str = Field(examples=["alice"])
    password: str


class PasswordChange(BaseModel):
    current: str
    new: str = Field(description="at least 10 characters")


class SetupStatus(BaseModel):
    needed: bool = Field(description="no user and no password-less choice yet: the setup link is waiting")
    passwordless: bool = Field(description="the password-less single-user mode is on")


class SetupRequest(BaseModel):
    token: str = Field(description="the token of the setup link the server printed at start")
    passwordless: bool = Field(False, description="no users: whoever is on this machine is the administrator")
    name: str | None = Field(None, description="the administrator's name (unless passwordless)")
    password: str | None = Field(None, description="the administrator's password (unless passwordless)")


class NewUser(BaseModel):
    name: str = Field(examples=["alice"])
    level: Level
    password: str = Field(description="at least 10 characters")


class UserChange(BaseModel):
    level: Level | None = None
    password: str | None = None


class TokenRequest(BaseModel):
    level: Level = Field(description="at most the caller's own level")
    days: int = Field(TOKEN_DAYS_DEFAULT, ge=1, le=TOKEN_DAYS_MAX, description="days until it expires")
    label: str = Field("", max_length=80, description="what the token is for")


class TokenModel(BaseModel):
    id: str
    label: str
    level: Level
    owner: str | None = Field(description="who created it (null: made from the data directory)")
    created: float
    expires: float


class NewToken(TokenModel):
    token: str = Field(description="the token itself, shown this once: send it as 'Authorization: Bearer …'")


def _user(user: User) -> UserModel:
    return UserModel(name=user.name, level=user.level)


def _account(account: Account) -> AccountModel:
    return AccountModel(name=account.name, level=account.level, created=account.created)


def _token(record: ApiToken) -> TokenModel:
    return TokenModel.model_validate(record.public())


def _signed_in(request: Request, response: Response, session: Session, user: User) -> UserModel:
    set_session_cookies(response, session, is_tls(request))
    return _user(user)


# ---- the caller, logging in and out -------------------------------------------------------------------------------


@router.get("/me", response_model=UserModel, dependencies=ANY_USER)
def get_me(user: Caller) -> UserModel:
    return _user(user)


@router.put("/me/password", status_code=status.HTTP_204_NO_CONTENT, dependencies=ANY_USER)
def change_password(body: PasswordChange, request: Request, user: Caller, control: Access) -> None:
    """Change one's own password; the current one is asked again (rate-limited like a login)."""
    control.change_password(user, body.current, body.new, request.client.host if request.client else "")


@router.post("/session", response_model=UserModel, dependencies=[Anyone], responses=LOGIN_ERRORS)
def log_in(body: Login, request: Request, response: Response, control: Access) -> UserModel:
    """Log in: sets the session cookie (HttpOnly) and the CSRF cookie, whose value every state-changing request
    repeats in ``X-CSRF-Token``. Failed logins are limited: 5 per user name and 20 per address in 15 minutes."""
    session, user = control.login(body.name, body.password, request.client.host if request.client else "")
    return _signed_in(request, response, session, user)


@router.delete("/session", status_code=status.HTTP_204_NO_CONTENT, dependencies=[Anyone])
def log_out(request: Request, response: Response, control: Access) -> None:
    control.sessions.close(request.cookies.get(SESSION_COOKIE, ""))
    clear_session_cookies(response, is_tls(request))


# ---- first start -----------------------------------------------------------------------------------------------


@router.get("/setup", response_model=SetupStatus, dependencies=[Anyone])
def get_setup(control: Access) -> SetupStatus:
    return SetupStatus(needed=control.store.needs_setup, passwordless=control.store.contents().passwordless)


@router.post("/setup", response_model=UserModel | None, dependencies=[Anyone], responses=LOGIN_ERRORS)
def post_setup(body: SetupRequest, request: Request, response: Response, control: Access) -> UserModel | None:
    """Redeem the setup link once: set the administrator (logged in at once), or choose password-less mode
    (loopback only; answers null)."""
    if body.passwordless:
        control.set_up_passwordless(body.token)
        return None
    if not body.name or not body.password:
        raise InvalidInput("setup needs the administrator's name and password, or passwordless: true")
    session, user = control.set_up_administrator(body.token, body.name, body.password)
    return _signed_in(request, response, session, user)


# ---- users -----------------------------------------------------------------------------------------------------


@router.get("/users", response_model=list[AccountModel], dependencies=ADMINISTRATOR)
def list_users(control: Access) -> list[AccountModel]:
    return [_account(account) for account in control.store.contents().accounts]


@router.post("/users", response_model=AccountModel, status_code=201, dependencies=ADMINISTRATOR)
def add_user(body: NewUser, control: Access) -> AccountModel:
    return _account(control.store.add_user(body.name, body.level, body.password))


@router.patch("/users/{name}", response_model=AccountModel, dependencies=ADMINISTRATOR)
def change_user(name: str, body: UserChange, control: Access) -> AccountModel:
    """A new level applies to the user's sessions at their next request; its tokens keep their own level."""
    if body.password is not None:
        control.store.set_password(name, body.password)
    if body.level is not None:
        control.store.set_level(name, body.level)
    return _account(control.store.account(name))


@router.delete("/users/{name}", status_code=status.HTTP_204_NO_CONTENT, dependencies=ADMINISTRATOR)
def remove_user(name: str, control: Access) -> None:
    """Remove the user, its sessions and its tokens (never the last administrator: 409)."""
    control.remove_user(name)


# ---- API tokens ------------------------------------------------------------------------------------------------


@router.get("/tokens", response_model=list[TokenModel], dependencies=ANY_USER)
def list_tokens(user: Caller, control: Access) -> list[TokenModel]:
    """One's own tokens; an administrator sees every token."""
    return [_token(record) for record in control.visible_tokens(user)]


@router.post("/tokens", response_model=NewToken, status_code=201, dependencies=ANY_USER)
def create_token(body: TokenRequest, user: Caller, control: Access) -> NewToken:
    text, record = control.create_token(user, body.level, body.days, body.label)
    return NewToken(**_token(record).model_dump(), token=text)


@router.delete("/tokens/{token_id}", status_code=status.HTTP_204_NO_CONTENT, dependencies=ANY_USER)
def revoke_token(token_id: str, user: Caller, control: Access) -> None:
    control.revoke_token(user, token_id)
