/** The top bar: brand, crumbs of the page, bus / user / server state, theme and shortcut buttons. */

import type { App } from "../../app";
import type { LiveHub } from "../../client/live";
import { LOCAL_USER, session } from "../../client/session";
import { h, type Child, type State } from "../../lib/dom";
import { showHelp } from "../help";
import { toggleTheme } from "../theme";

export interface ServerState {
  state: "connecting" | "online" | "offline";
  text: string;
}

export function topBar(app: App, crumbs: State<Child>): HTMLElement {
  return h("header", { class: "topbar" },
    h("a", { class: "brand", href: "/" }, "Servo Studio"),
    h("nav", { class: "crumbs", "aria-label": "Location" }, crumbs),
    h("span", { class: "spacer" }),
    busStatus(app.live),
    userStatus(app.live),
    serverStatus(app.server),
    h("button", { class: "small", title: "Switch theme (T)", "data-testid": "theme-toggle", onclick: () => toggleTheme() }, "Theme"),
    h("button", { class: "small", title: "Keyboard shortcuts (?)", onclick: () => showHelp() }, "?"));
}

/** The server's buses: each with its state, green when all are connected. */
export function busStatus(live: LiveHub): HTMLElement {
  return h("span", { class: "pill", "data-testid": "bus-status", title: "Buses of the communication server" }, () => {
    const buses = live.busStates.val;
    if (buses.length === 0) return [h("span", { class: "dot idle" }), "No bus connected"];
    const tone = buses.every((bus) => bus.state === "connected") ? "ok" : "warn";
    return [h("span", { class: `dot ${tone}` }), buses.map((bus) => `${bus.name}: ${bus.state}`).join(" · ")];
  });
}

/** Who is logged in and at which level (docs/security.md), with a way out unless it is the password-less user. */
export function userStatus(live: LiveHub): HTMLElement {
  return h("span", { class: "pill", "data-testid": "user-status", title: "User and level" }, () => {
    const user = live.userState.val;
    if (!user) return "not logged in";
    const logOut = h("button", { class: "small", "data-testid": "log-out", onclick: () => void leave() }, "Log out");
    return [`${user.name} · ${user.level}`, user.name === LOCAL_USER ? null : logOut];
  });
}

async function leave(): Promise<void> {
  await session.logOut();
  window.location.assign("/login");
}

export function serverStatus(server: State<ServerState>): HTMLElement {
  return h("span", { class: "pill server-status", "data-testid": "server-status", "data-state": () => server.val.state },
    h("span", { class: "dot" }), () => server.val.text);
}
