/** Logging in and out, and the first start's one-time setup (docs/security.md). */

import { del, get, post, type UserInfo } from "./api";
import type { Schemas } from "./schema-types";

export type SetupStatus = Schemas["SetupStatus"];

/** The password-less single-user mode's caller: there is nobody to log out. */
export const LOCAL_USER = "local";

export const session = {
  /** Sets the session cookie (HttpOnly) and the CSRF cookie the API client repeats. */
  logIn: (name: string, password: string) => post<UserInfo>("/api/session", { name, password }),
  logOut: () => del<void>("/api/session"),
  setupStatus: () => get<SetupStatus>("/api/setup"),
  /** Redeem the setup link: the first administrator, logged in at once. */
  setUpAdministrator: (token: string, name: string, password: string) =>
    post<UserInfo>("/api/setup", { token, name, password }),
  /** Redeem the setup link: no users, whoever is on this computer is the administrator. */
  setUpPasswordless: (token: string) => post<null>("/api/setup", { token, passwordless: true }),
};
