import { afterEach, describe, expect, it } from "vitest";
import { csrfToken, onUnauthenticated, request } from "../client/api";
import { parsePath } from "../lib/router";

/** A fetch that records the headers it was called with and answers `status`. */
function recording(status = 200): { fetch: typeof fetch; headers: Record<string, string>[] } {
  const headers: Record<string, string>[] = [];
  const impl = (async (_path: string, init: RequestInit) => {
    headers.push({ ...(init.headers as Record<string, string>) });
    return new Response(status === 204 ? null : JSON.stringify({ detail: "log in", kind: "unauthenticated" }), { status });
  }) as unknown as typeof fetch;
  return { fetch: impl, headers };
}

describe("session", () => {
  afterEach(() => {
    document.cookie = "servostudio_csrf=; expires=Thu, 01 Jan 1970 00:00:00 GMT";
    onUnauthenticated(() => undefined);
  });

  it("reads the CSRF token from its cookie", () => {
    expect(csrfToken("a=1; servostudio_csrf=abc%2Ddef; b=2")).toBe("abc-def");
    expect(csrfToken("a=1")).toBeNull();
  });

  it("repeats the CSRF token on changes only", async () => {
    document.cookie = "servostudio_csrf=token123";
    const server = recording(204);
    await request("POST", "/api/projects", {}, server.fetch);
    await request("GET", "/api/projects", undefined, server.fetch);
    expect(server.headers[0]["X-CSRF-Token"]).toBe("token123");
    expect(server.headers[1]["X-CSRF-Token"]).toBeUndefined();
  });

  it("sends no CSRF header without a session", async () => {
    const server = recording(204);
    await request("DELETE", "/api/buses/sim", undefined, server.fetch);
    expect(server.headers[0]["X-CSRF-Token"]).toBeUndefined();
  });

  it("tells the app when the server wants a login", async () => {
    let asked = 0;
    onUnauthenticated(() => asked++);
    await expect(request("GET", "/api/me", undefined, recording(401).fetch)).rejects.toMatchObject({ status: 401, kind: "unauthenticated" });
    expect(asked).toBe(1);
  });

  it("routes the login and setup pages", () => {
    expect(parsePath("/login", "?next=%2Fbus").route).toEqual({ page: "login" });
    expect(parsePath("/setup", "?token=abc")).toEqual({ route: { page: "setup" }, query: { token: "abc" } });
  });
});
