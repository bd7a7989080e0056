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

  it("shows the server's message with its kind and class, and the problems of a malformed request", async () => {
    await expect(request("GET", "/x", undefined, answer({ detail: "0x60F9,2: 70000 above 65535" }, 422)))
      .rejects.toThrow("0x60F9,2: 70000 above 65535");
    const conflict = request("PUT", "/x", {}, answer({ detail: "changed meanwhile", error: "ConflictError", kind: "conflict" }, 409));
    await expect(conflict).rejects.toMatchObject({ status: 409, kind: "conflict", error: "ConflictError", message: "changed meanwhile" });
    const malformed = answer({ detail: [{ loc: ["body", "name"], msg: "Field required" }], error: "RequestValidationError", kind: "invalid_input" }, 422);
    await expect(request("POST", "/x", {}, malformed)).rejects.toMatchObject({ message: "name: Field required", kind: "invalid_input" });
    await expect(request("GET", "/x", undefined, answer({}, 404))).rejects.toMatchObject({ message: "/x: HTTP 404", kind: "" });
    await expect(request("GET", "/x", undefined, answer({}, 404))).rejects.toBeInstanceOf(ApiError);
  });

  it("writes addresses the way the server reads them", () => {
    expect(projectAddress(0x60f9, 2)).toBe("0x60F9,2");
    expect(projectAddress(0x1000, 0)).toBe("0x1000,0");
  });
});
