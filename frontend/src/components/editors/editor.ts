/**
 * What every value editor shares: the text it shows follows the entry's current raw value until the user types
 * (then it keeps what was typed, whatever arrives), Enter checks it through `parseValue` (unit and scale, range)
 * and emits the raw value, a refusal is kept in `error` and marks the control invalid.
 */

import { derive, h, state, valueOf, type Bindable, type State } from "../../lib/dom";
import type { OdVariable, Scalar } from "../../lib/od";
import { parseValue, type ParsedValue } from "../../lib/values";

export interface EditorOptions {
  /** The entry's current raw value (drive, else project, else default); shown until the user edits. */
  value: Bindable<Scalar>;
  /** A valid value was submitted (Enter, or `submit()`): the raw value to write. */
  onSubmit?: (raw: number | string) => void;
  /** A submitted text was refused: the reason (also kept in `error`). */
  onRefuse?: (reason: string) => void;
  /** Escape in the control (the parameter editor returns to its table). */
  onEscape?: () => void;
  /** Attributes of the control: `data-testid`, `aria-label`, `style`, `data-editor`. */
  attrs?: Record<string, unknown>;
}

export interface ValueEditor {
  readonly element: HTMLInputElement | HTMLSelectElement;
  /** What the control shows: the current value's text until edited, then the user's. */
  readonly text: State<string>;
  /** True once the user changed the text: it no longer follows the current value. */
  readonly edited: State<boolean>;
  /** The reason the last check refused the text ("" when it was valid). */
  readonly error: State<string>;
  /** Set the text as if the user had typed it (a bit checkbox, the pointer picker). */
  setText(text: string): void;
  /** Check the text; a valid value is returned and emitted (`onSubmit`), a refusal kept in `error` (`onRefuse`). */
  submit(): ParsedValue;
  /** Follow the current value again and forget the refusal (after a write). */
  revert(): void;
}

/** The reactive part of an editor, without its control. */
export class EditorModel {
  private readonly typed = state<string | null>(null);
  readonly text: State<string>;
  readonly edited: State<boolean>;
  readonly error = state("");

  constructor(
    private readonly variable: OdVariable,
    private readonly options: EditorOptions,
    show: (raw: Scalar) => string,
  ) {
    this.text = derive(() => this.typed.val ?? show(valueOf(options.value)));
    this.edited = derive(() => this.typed.val !== null);
  }

  setText(text: string): void {
    this.typed.val = text;
  }

  submit(): ParsedValue {
    const parsed = parseValue(this.variable, this.text.rawVal);
    this.error.val = parsed.ok ? "" : parsed.error;
    if (parsed.ok) this.options.onSubmit?.(parsed.raw);
    else this.options.onRefuse?.(parsed.error);
    return parsed;
  }

  revert(): void {
    this.typed.val = null;
    this.error.val = "";
  }

  /** Enter submits, Escape leaves the control. */
  onKey(event: KeyboardEvent): void {
    if (event.key === "Enter") {
      event.preventDefault();
      this.submit();
    } else if (event.key === "Escape") {
      this.options.onEscape?.();
    }
  }
}

/** Assemble the editor from its model and control. */
export function editorOf(model: EditorModel, element: HTMLInputElement | HTMLSelectElement): ValueEditor {
  return {
    element,
    text: model.text,
    edited: model.edited,
    error: model.error,
    setText: (text) => model.setText(text),
    submit: () => model.submit(),
    revert: () => model.revert(),
  };
}

/** A one-line text field bound to the model (the number, text, bits and pointer editors). */
export function textField(model: EditorModel, options: EditorOptions, extra: Record<string, unknown> = {}): HTMLInputElement {
  const input: HTMLInputElement = h("input", {
    type: "text", spellcheck: "false", autocomplete: "off", ...extra, ...options.attrs,
    class: () => (model.error.val ? "invalid" : ""),
    value: model.text,
    oninput: () => model.setText(input.value),
    onkeydown: (event: KeyboardEvent) => model.onKey(event),
  });
  return input;
}
