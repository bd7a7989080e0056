/**
 * Logging in, and the first start: the page of the one-time setup link the server printed, on which the owner sets
 * the Administrator's password or chooses password-less use on this computer (docs/security.md).
 */

import type { App, Page, PageContext } from "../app";
import { getMe, type UserInfo } from "../client/api";
import { session } from "../client/session";
import { failure, messageView, type Message } from "../components/ui";
import { h, state, type State } from "../lib/dom";

export function loginPage(context: PageContext): Page {
  const { app } = context;
  const name = h("input", { type: "text", autocomplete: "username", "data-testid": "login-name" });
  const password = h("input", { type: "password", autocomplete: "current-password", "data-testid": "login-password" });
  const error = state<Message | null>(null);
  const submit = () => attempt(app, error, "login-error", () => session.logIn(name.value.trim(), password.value));
  return {
    title: "Log in",
    element: form("Log in", [
      h("label", { class: "field" }, "User", name),
      h("label", { class: "field" }, "Password", password),
    ], error, h("button", { class: "primary", type: "submit", "data-testid": "login-submit" }, "Log in"), submit),
  };
}

export async function setupPage(context: PageContext): Promise<Page> {
  const { app, location } = context;
  if (!(await session.setupStatus()).needed) {
    return { title: "Setup", element: h("div", { class: "page" }, h("div", { class: "message ok", "data-testid": "setup-done" },
      "Setup is done. ", h("a", { href: "/login" }, "Log in"))) };
  }
  const token = location.query.token ?? "";
  const name = h("input", { type: "text", value: "admin", autocomplete: "username", "data-testid": "setup-name" });
  const password = h("input", { type: "password", autocomplete: "new-password", "data-testid": "setup-password" });
  const again = h("input", { type: "password", autocomplete: "new-password", "data-testid": "setup-password-again" });
  const error = state<Message | null>(null);
  const administrator = () => attempt(app, error, "setup-error", () => {
    if (password.value !== again.value) throw new Error("The two passwords differ.");
    return session.setUpAdministrator(token, name.value.trim(), password.value);
  });
  const passwordless = () => attempt(app, error, "setup-error", async () => (await session.setUpPasswordless(token), getMe()));
  return {
    title: "Setup",
    element: form("Set up Servo Studio", [
      h("p", { class: "muted" }, "Set the Administrator's password (at least 10 characters). There is no default password."),
      h("label", { class: "field" }, "Administrator", name),
      h("label", { class: "field" }, "Password", password),
      h("label", { class: "field" }, "Password again", again),
    ], error, [
      h("button", { class: "primary", type: "submit", "data-testid": "setup-submit" }, "Set the password"),
      h("button", { type: "button", "data-testid": "setup-passwordless", onclick: () => void passwordless(),
        title: "No users: whoever uses this computer is the administrator; refused for a server other computers reach" },
      "Use without password on this computer"),
    ], administrator),
  };
}

/** A centred form; Enter or the submit button runs `submit`. */
function form(title: string, fields: Node[], error: State<Message | null>, actions: Node | Node[], submit: () => Promise<void>): HTMLElement {
  return h("div", { class: "page" }, h("form", { class: "panel", style: { maxWidth: "420px", margin: "40px auto" },
    onsubmit: (event: Event) => { event.preventDefault(); void submit(); } },
  h("div", { class: "panel-body" }, h("h1", null, title), fields, messageView(error),
    h("div", { style: { display: "flex", flexWrap: "wrap", gap: "8px", marginTop: "10px" } }, actions))));
}

/** Run a login or setup; on success the app continues where the user was going, else the error is shown. */
async function attempt(app: App, error: State<Message | null>, testid: string, signIn: () => Promise<UserInfo>): Promise<void> {
  try {
    error.val = null;
    app.signedIn(await signIn());
  } catch (problem) {
    error.val = failure(problem, testid);
  }
}
