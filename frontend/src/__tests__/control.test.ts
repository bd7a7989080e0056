import { afterEach, describe, expect, it, vi } from "vitest";
import { setMotionClient } from "../client/api";
import { auditApi, auditQuery, holderText, type AxisControl } from "../client/control";
import { controllerPanel, type ControllerProps } from "../components/dashboard/controller";
import { state } from "../lib/dom";

const testid = (root: HTMLElement, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const held = (client: string | null): AxisControl => ({
  bus: "sim", node: 1, requests: [], holder: client === null ? null : { client, user: client === "me" ? "alice" : "bob", since: 0 },
});

function panel(control: AxisControl | null, overrides: Partial<ControllerProps> = {}) {
  const props: ControllerProps = {
    control: state(control), askedBy: state<string | null>(null), busy: state(false), mayTakeOver: true,
    onArm: vi.fn(), onRelease: vi.fn(), onRequest: vi.fn(), onTakeOver: vi.fn(), ...overrides,
  };
  return { props, element: controllerPanel(props) };
}

afterEach(() => setMotionClient(null));

describe("controller panel", () => {
  it("offers to arm an axis nobody holds", () => {
    const { props, element } = panel(held(null));
    expect(testid(element, "controller-holder")!.textContent).toBe("Not armed: nobody answers for this axis");
    testid(element, "control-arm")!.click();
    expect(props.onArm).toHaveBeenCalled();
  });

  it("lets this page release what it holds, and shows who asks for it", () => {
    setMotionClient("me");
    const { props, element } = panel(held("me"));
    expect(testid(element, "controller-holder")!.textContent).toBe("Armed by this page");
    expect(testid(element, "control-arm")).toBeNull();
    props.askedBy.val = "bob";
    expect(testid(element, "controller-asked")!.textContent).toContain("bob asks for this axis");
    testid(element, "control-hand-over")!.click();
    expect(props.onRelease).toHaveBeenCalled();
  });

  it("names another holder and offers to ask, and to take over only to an Expert", () => {
    setMotionClient("me");
    const { element } = panel(held("other"));
    expect(testid(element, "controller-holder")!.textContent).toBe("Armed by bob (client other)");
    expect(testid(element, "control-request")).not.toBeNull();
    expect(testid(element, "control-take-over")).not.toBeNull();
    const lower = panel(held("other"), { mayTakeOver: false }).element;
    expect(testid(lower, "control-take-over")).toBeNull();
  });

  it("follows the holder as events change it", () => {
    const { props, element } = panel(held(null));
    props.control.val = held("other");
    expect(testid(element, "control-request")).not.toBeNull();
    expect(holderText(null)).toBe("…");
  });
});

describe("audit queries", () => {
  it("leave empty filters out and carry the page and the export format", () => {
    expect(auditQuery({ axis: "sim:1", user: "" }, { offset: "100" })).toBe("axis=sim%3A1&offset=100");
    expect(auditApi.exportUrl({ since: "2h" }, "csv")).toBe("/api/audit/export?since=2h&format=csv");
  });
});
