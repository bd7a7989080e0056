import { beforeAll, beforeEach, describe, expect, it, vi } from "vitest";
import type { ProjectParameter } from "../client/api";
import type { DriveCell } from "../components/parameters/store";
import type { Dictionary, Entry } from "../lib/od";
import type { Location } from "../lib/router";
import { ParameterEditor, type ParameterSources } from "../pages/parameters";
import { entry, type } from "./fixtures";

beforeAll(() => {
  // jsdom has no layout: the virtual list only needs the observer to exist.
  globalThis.ResizeObserver ??= class {
    observe(): void {}
    unobserve(): void {}
    disconnect(): void {}
  } as unknown as typeof ResizeObserver;
});
beforeEach(() => localStorage.clear());

const kpv = entry(0x60f9, { subindex: 2, name: "KPv", group: "Servo Loops" }, { name: "Speed loop", kind: "RECORD" });
const kiv = entry(0x60f9, { subindex: 3, name: "KIv", group: "Servo Loops", write_level: "expert" }, { name: "Speed loop", kind: "RECORD" });
const rated = entry(0x6075, { name: "Motor rated current", group: "Motor", unit: "A", scale: 0.001, data_type: "INTEGER32" });
kiv.object = kpv.object;
kpv.object.subs = [kpv.variable, kiv.variable];
const dictionary = { groups: ["Servo Loops", "Motor"], objects: [kpv.object, rated.object] } as Dictionary;
const driveValues: Record<string, number> = { [kpv.key]: 200, [kiv.key]: 50, [rated.key]: 2500 };

function projectRow(item: Entry, value: number): ProjectParameter {
  return { index: item.object.index, subindex: item.variable.subindex, value, file: "DRIVEPAR.TXT", editable: true, not_editable_reason: null } as ProjectParameter;
}

function editor(query: Record<string, string> = {}) {
  const read = vi.fn(async (list: Entry[]) => new Map<string, DriveCell>(list.map((item) => [item.key, { raw: driveValues[item.key] }])));
  const sources: ParameterSources = {
    drive: { online: () => true, read, write: vi.fn(async (_entry: Entry, raw: number | string) => raw) },
    project: { load: async () => [projectRow(kpv, 200), projectRow(kiv, 60)], write: vi.fn(async () => []), reset: vi.fn(async () => []) },
    onQuery: vi.fn(),
  };
  const view = new ParameterEditor(dictionary, sources, { route: { page: "axis" }, query } as unknown as Location);
  document.body.replaceChildren(view.element);
  return { view, sources, read, element: view.element };
}

const find = (root: HTMLElement, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const rowOf = (root: HTMLElement, address: string) => root.querySelector<HTMLElement>(`.prow.entry[data-address="${address}"]`);

describe("parameter editor", () => {
  it("lists the entries grouped, reads the drive values of the rows in view and binds them", async () => {
    const { view, element, read } = editor();
    await view.start();
    expect(find(element, "param-count")!.textContent).toBe("3 of 3 entries");
    expect([...element.querySelectorAll(".prow.group")].map((row) => row.firstChild!.textContent)).toEqual(["Servo Loops", "Motor"]);
    await vi.waitFor(() => expect(rowOf(element, "0x60F9.3")!.querySelector("[data-col=drive]")!.textContent).toBe("50"));
    expect(read).toHaveBeenCalled();
    expect(rowOf(element, "0x60F9.3")!.querySelector(".differs")!.getAttribute("title")).toBe("differs from the project value 60");
    expect(rowOf(element, "0x60F9.2")!.querySelector(".differs")).toBeNull();
    expect(rowOf(element, "0x60F9.2")!.querySelector("[data-col=project]")!.textContent).toBe("200");
    view.dispose();
  });

  it("filters on typing (debounced), keeps the query in the URL, and follows a URL change", async () => {
    const { view, element, sources } = editor();
    type(find(element, "param-search") as HTMLInputElement, "rated");
    await vi.waitFor(() => expect(find(element, "param-count")!.textContent).toBe("1 of 3 entries"));
    expect(sources.onQuery).toHaveBeenCalledWith({ q: "rated", group: undefined });
    expect(find(element, "detail-name")!.textContent).toBe("Motor rated current");
    view.update({ query: { group: "Servo Loops" } } as unknown as Location);
    expect(find(element, "param-count")!.textContent).toBe("2 of 3 entries");
    expect((find(element, "param-search") as HTMLInputElement).value).toBe("");
    expect((find(element, "param-group") as HTMLSelectElement).value).toBe("Servo Loops");
    view.dispose();
  });

  it("selects a clicked row and writes the typed value to the drive and the project when chosen", async () => {
    const { view, element, sources } = editor({ q: "KIv" });
    await view.start();
    rowOf(element, "0x60F9.3")!.click();
    expect(rowOf(element, "0x60F9.3")!.classList.contains("selected")).toBe(true);
    await vi.waitFor(() => expect(find(element, "detail-drive-value")!.textContent).toBe("50"));
    const both = find(element, "target-both") as HTMLInputElement;
    both.checked = true;
    both.dispatchEvent(new Event("change"));
    type(find(element, "param-editor") as HTMLInputElement, "77");
    find(element, "param-write")!.click();
    await vi.waitFor(() => expect(element.querySelector("[data-status]")!.textContent).toBe("0x60F9.3 = 77 written to the drive and the project"));
    expect(sources.drive!.write).toHaveBeenCalledWith(kiv, 77);
    expect(sources.project!.write).toHaveBeenCalledWith([{ entry: kiv, raw: 77 }]);
    expect(find(element, "detail-drive-value")!.textContent).toBe("77");
    view.dispose();
  });

  it("shows the user level an entry needs to be written, and read-only for one nobody writes", async () => {
    const { view, element } = editor({ q: "KIv" });
    await view.start();
    rowOf(element, "0x60F9.3")!.click();
    expect(find(element, "detail-write-level")!.textContent).toBe("Expert or higher");
    const statusword = entry(0x6041, { name: "Statusword", access: "ro", write_level: null });
    const levels = new ParameterEditor({ groups: ["General"], objects: [statusword.object] } as Dictionary, { drive: null, project: null, onQuery: vi.fn() },
      { route: { page: "axis" }, query: {} } as unknown as Location);
    document.body.replaceChildren(levels.element);
    await levels.start();
    expect(find(levels.element, "detail-write-level")!.textContent).toBe("read-only");
    levels.dispose();
    view.dispose();
  });

  it("shows only the differing entries once every value is read", async () => {
    const { view, element } = editor();
    await view.start(); // only the first entry (selected) is read yet; KIv, which differs, is not
    const only = find(element, "param-only-diff") as HTMLInputElement;
    only.checked = true;
    only.dispatchEvent(new Event("change"));
    await vi.waitFor(() => expect(find(element, "param-count")!.textContent).toBe("1 of 3 entries"));
    expect([...element.querySelectorAll<HTMLElement>(".prow.entry")].map((row) => row.dataset.address)).toEqual(["0x60F9.3"]);
    expect(find(element, "param-write-changed")!.textContent).toBe("Write changed → drive (1)");
    only.checked = false;
    only.dispatchEvent(new Event("change"));
    expect(find(element, "param-count")!.textContent).toBe("3 of 3 entries");
    view.dispose();
  });
});
