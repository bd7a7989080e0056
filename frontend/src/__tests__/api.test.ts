import { describe, expect, it } from "vitest";
import { ApiError, getHealth, projectAddress, request } from "../client/api";

const answer = (body: unknown, status: number) =>
  (async () => new Response(JSON.stringify(body), { status, headers: { "Content-Type": "application/json" } })) as unknown as typeof fetch;

describe("api", () => {
  it("rejects a non-2xx answer without a body with the path and status", async () => {
    const failing = (async () => new Response("", { status: 500 })) as unknown as typeof fetch;
    await expect(getHealth(failing)).rejects.toThrow("/api/health: HTTP 500");
  });

  it("parses the health document", async () => {
    const ok = (async () => Response.json({ status: "ok", version: "1.2.3" })) as unknown as typeof fetch;
    await expect(getHealth(ok)).resolves.toEqual({ status: "ok", version: "1.2.3" });
  });

  it("shows the server's message: plain detail, {error, message} and validation lists", async () => {
    await expect(request("GET", "/x", undefined, answer({ detail: "0x60F9,2: 70000 above 65535" }, 422)))
      .rejects.toThrow("0x60F9,2: 70000 above 65535");
    const conflict = request("PUT", "/x", {}, answer({ detail: { error: "ConflictError", message: "changed meanwhile" } }, 409));
    await expect(conflict).rejects.toMatchObject({ status: 409, kind: "ConflictError", message: "changed meanwhile" });
    await expect(request("POST", "/x", {}, answer({ detail: [{ loc: ["body", "name"], msg: "Field required" }] }, 422)))
      .rejects.toThrow("name: Field required");
    await expect(request("GET", "/x", undefined, answer({}, 404))).rejects.toBeInstanceOf(ApiError);
  });

  it("writes addresses the way the server reads them", () => {
    expect(projectAddress(0x60f9, 2)).toBe("0x60F9,2");
    expect(projectAddress(0x1000, 0)).toBe("0x1000,0");
  });
});
