import { describe, expect, it, vi } from "vitest";
import { bitFields, editorKind, enumEditor, enumList, numberEditor, pointerTarget, textEditor, valueEditor } from "../components/editors";
import { state } from "../lib/dom";
import type { Scalar } from "../lib/od";
import { choose, entry, press, type, variable } from "./fixtures";

const current = variable({ name: "Current limit", unit: "A", scale: 0.001, low: 0, high: 20000 });

describe("number editor", () => {
  it("shows the current raw value in the entry's unit and follows it until the user types", () => {
    const value = state<Scalar>(2500);
    const editor = numberEditor(current, { value });
    const input = editor.element as HTMLInputElement;
    expect(input.value).toBe("2.5");
    value.val = 3000;
    expect(input.value).toBe("3");
    type(input, "4");
    value.val = 1000;
    expect(input.value).toBe("4");
    expect(editor.edited.val).toBe(true);
    editor.revert();
    expect(input.value).toBe("1");
  });

  it("emits the raw value of what was typed on Enter", () => {
    const onSubmit = vi.fn();
    const input = numberEditor(current, { value: 0, onSubmit }).element as HTMLInputElement;
    type(input, "2.5");
    press(input, "Enter");
    expect(onSubmit).toHaveBeenCalledWith(2500);
    type(input, "0x10");
    press(input, "Enter");
    expect(onSubmit).toHaveBeenLastCalledWith(16000);
  });

  it("refuses a decimal comma and an out-of-range value with the reason, emitting nothing", () => {
    const onSubmit = vi.fn();
    const editor = numberEditor(current, { value: 0, onSubmit });
    const input = editor.element as HTMLInputElement;
    type(input, "2,5");
    expect(editor.submit()).toEqual({ ok: false, error: '"2,5": use "." as decimal separator' });
    expect(input.classList.contains("invalid")).toBe(true);
    type(input, "25");
    press(input, "Enter");
    expect(editor.error.val).toBe("25 is outside 0 … 20 A");
    expect(onSubmit).not.toHaveBeenCalled();
    type(input, "20");
    press(input, "Enter");
    expect(onSubmit).toHaveBeenCalledWith(20000);
    expect(editor.error.val).toBe("");
    expect(input.classList.contains("invalid")).toBe(false);
  });

  it("refuses a value between two steps of the scale", () => {
    const editor = numberEditor(variable({ scale: 0.5 }), { value: 0 });
    type(editor.element as HTMLInputElement, "0.3");
    expect(editor.submit()).toEqual({ ok: false, error: "0.3 is not a multiple of 0.5" });
  });

  it("passes the given attributes and calls onEscape", () => {
    const onEscape = vi.fn();
    const input = numberEditor(current, { value: 0, onEscape, attrs: { "data-testid": "qt-velocity" } }).element;
    expect(input.dataset.testid).toBe("qt-velocity");
    press(input, "Escape");
    expect(onEscape).toHaveBeenCalledOnce();
  });
});

describe("text editor", () => {
  it("shows the text and emits it as typed", () => {
    const onSubmit = vi.fn();
    const editor = textEditor(variable({ data_type: "VISIBLE_STRING" }), { value: "axis 1", onSubmit });
    const input = editor.element as HTMLInputElement;
    expect(input.value).toBe("axis 1");
    type(input, "axis 2 ");
    press(input, "Enter");
    expect(onSubmit).toHaveBeenCalledWith("axis 2 ");
  });
});

const modes = variable({ name: "Modes of operation", data_type: "INTEGER8", enum: { "1": "Profile position", "3": "Profile velocity", "-1": "Analog speed" } });

describe("enum editor", () => {
  it("lists the enumeration in value order with the current value selected", () => {
    const value = state<Scalar>(3);
    const select = enumEditor(modes, { value }).element as HTMLSelectElement;
    expect([...select.options].map((option) => option.text)).toEqual(["Analog speed (-1)", "Profile position (1)", "Profile velocity (3)"]);
    expect(select.value).toBe("3");
    value.val = 1;
    expect(select.value).toBe("1");
  });

  it("adds an option for a value the enumeration does not name, and drops it once another is chosen", () => {
    const editor = enumEditor(modes, { value: 0, unknownLabel: (value) => `${value} (no mode)` });
    const select = editor.element as HTMLSelectElement;
    expect(select.selectedOptions[0].text).toBe("0 (no mode)");
    choose(select, "-1");
    expect(select.options).toHaveLength(3);
    expect(editor.text.val).toBe("-1");
    expect(enumEditor(modes, { value: 9 }).element.querySelector("option")!.textContent).toBe("9 (not in the list)");
  });

  it("keeps the user's choice when the current value changes, and emits it as a number", () => {
    const value = state<Scalar>(1);
    const onSubmit = vi.fn();
    const select = enumEditor(modes, { value, onSubmit }).element as HTMLSelectElement;
    choose(select, "3");
    value.val = -1;
    expect(select.value).toBe("3");
    press(select, "Enter");
    expect(onSubmit).toHaveBeenCalledWith(3);
  });

  it("shows the first option while there is no value, and marks the current value in the list", () => {
    expect((enumEditor(modes, { value: null }).element as HTMLSelectElement).value).toBe("-1");
    const value = state<Scalar>(3);
    const list = enumList(modes, value);
    expect([...list.querySelectorAll(".current")].map((cell) => cell.textContent)).toEqual(["3", "Profile velocity"]);
    value.val = 1;
    expect([...list.querySelectorAll(".current")].map((cell) => cell.textContent)).toEqual(["1", "Profile position"]);
  });
});

const control = variable({ name: "Controlword", data_type: "UNSIGNED8", bits: [
  { first: 3, last: 3, name: "Enable operation" }, { first: 0, last: 0, name: "Switch on" }, { first: 4, last: 6, name: "Mode bits" },
] });

describe("bits editor", () => {
  it("shows the word in hex and its fields in bit order, the set ones marked", () => {
    const value = state<Scalar>(0x09);
    const editor = valueEditor(control, { value });
    expect((editor.element as HTMLInputElement).value).toBe("0x09");
    const fields = bitFields(control, value, null);
    expect([...fields.querySelectorAll(".bits > span:nth-child(3n+2)")].map((cell) => cell.textContent)).toEqual(["Switch on", "Enable operation", "Mode bits"]);
    expect([...fields.querySelectorAll(".on")].map((cell) => cell.textContent)).toEqual(["Switch on", "1", "Enable operation", "1"]);
    expect(fields.querySelector("input")).toBeNull();
    value.val = 0x30;
    expect([...fields.querySelectorAll(".on")].map((cell) => cell.textContent)).toEqual(["Mode bits", "3"]);
  });

  it("ticks a bit into the typed word, follows what is typed, and emits the raw word", () => {
    const onSubmit = vi.fn();
    const editor = valueEditor(control, { value: 0x01, onSubmit });
    const fields = bitFields(control, 0x01, editor);
    const boxes = [...fields.querySelectorAll<HTMLInputElement>("input[type=checkbox]")];
    expect(boxes.map((box) => box.checked)).toEqual([true, false]);
    boxes[1].checked = true;
    boxes[1].dispatchEvent(new Event("change"));
    expect((editor.element as HTMLInputElement).value).toBe("0x09");
    type(editor.element as HTMLInputElement, "0x08");
    expect(boxes.map((box) => box.checked)).toEqual([false, true]);
    expect(editor.submit()).toEqual({ ok: true, raw: 8 });
    expect(onSubmit).toHaveBeenCalledWith(8);
  });

  it("refuses a word wider than the data type", () => {
    const editor = valueEditor(control, { value: 0 });
    type(editor.element as HTMLInputElement, "0x1FF");
    expect(editor.submit()).toEqual({ ok: false, error: "0x1FF is outside 0x00 … 0xFF" });
  });
});

describe("pointer editor", () => {
  const pointer = variable({ name: "IN1 destination", data_type: "UNSIGNED32", is_pointer: true });
  const targets = [entry(0x60fd, { name: "Digital inputs", data_type: "UNSIGNED32", pdo_mappable: true }), entry(0x2000, { name: "Not mappable" })];

  it("shows the target of the current value symbolically and picks it", () => {
    const value = state<Scalar>(0x60fd0010);
    const editor = valueEditor(pointer, { value });
    expect((editor.element as HTMLInputElement).value).toBe("0x60FD0010");
    const section = pointerTarget(value, targets, editor);
    expect(section.textContent).toContain("Points to 0x60FD.0 / 16 · Digital inputs");
    const picker = section.querySelector<HTMLSelectElement>("[data-testid=pointer-picker]")!;
    expect(picker.value).toBe(targets[0].key);
    expect(picker.options).toHaveLength(2);
    value.val = 0;
    expect(section.textContent).toContain("Points to not linked");
    expect(picker.value).toBe("");
  });

  it("writes the chosen target and bit into the editor, which emits the raw word", () => {
    const onSubmit = vi.fn();
    const editor = valueEditor(pointer, { value: 0, onSubmit });
    const section = pointerTarget(0, targets, editor);
    const bit = section.querySelector<HTMLInputElement>("[aria-label='Bit or size']")!;
    choose(section.querySelector<HTMLSelectElement>("[data-testid=pointer-picker]")!, targets[0].key);
    expect((editor.element as HTMLInputElement).value).toBe("0x60FD0000");
    type(bit, "17");
    expect((editor.element as HTMLInputElement).value).toBe("0x60FD0011");
    type(bit, "300");
    expect((editor.element as HTMLInputElement).value).toBe("0x60FD0011");
    editor.submit();
    expect(onSubmit).toHaveBeenCalledWith(0x60fd0011);
  });

  it("disables the picker without an editor", () => {
    expect(pointerTarget(0, targets, null).querySelector<HTMLSelectElement>("select")!.disabled).toBe(true);
  });
});

describe("editor choice", () => {
  it("gives each kind of value its editor", () => {
    expect(editorKind(modes)).toBe("enum");
    expect(editorKind(control)).toBe("bits");
    expect(editorKind(variable({ is_pointer: true, data_type: "UNSIGNED32" }))).toBe("pointer");
    expect(editorKind(variable({ data_type: "VISIBLE_STRING" }))).toBe("text");
    expect(editorKind(variable({ data_type: "OCTET_STRING" }))).toBe("text");
    expect(editorKind(current)).toBe("number");
    expect(editorKind(variable({ data_type: "REAL32", enum: { "1": "one" } }))).toBe("number");
  });
});
