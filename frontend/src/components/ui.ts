/** Small shared widgets: toasts, modal dialogs and form dialogs, message lines, downloads and file pickers. */

import { h, state, type State } from "../lib/dom";

/** A line of feedback under a toolbar or in a dialog; `testid` names it for the browser tests. */
export interface Message {
  text: string;
  tone: "error" | "warn" | "ok";
  testid?: string;
}

export const failure = (error: unknown, testid?: string): Message => ({ text: errorText(error), tone: "error", testid });

/** The message of `message` (nothing while it is null). */
export function messageView(message: State<Message | null>): HTMLElement {
  return h("div", null, () => {
    const current = message.val;
    return current ? h("div", { class: `message ${current.tone}`, "data-testid": current.testid }, current.text) : null;
  });
}

let toastArea: HTMLElement | null = null;

/** A short message in the corner; errors stay until clicked, confirmations fade after a few seconds. */
export function toast(message: string, kind: "ok" | "error" | "info" = "info"): void {
  if (!toastArea || !toastArea.isConnected) {
    toastArea = h("div", { class: "toast-area", role: "status", "aria-live": "polite" });
    document.body.append(toastArea);
  }
  const item = h("div", { class: `toast ${kind}`, "data-testid": "toast", onclick: () => item.remove() }, message);
  toastArea.append(item);
  if (kind !== "error") setTimeout(() => item.remove(), 4000);
}

export interface DialogHandle {
  close(): void;
  body: HTMLElement;
  actions: HTMLElement;
}

/** A modal dialog; Escape or a click beside it closes it (and calls `onClose`). */
export function openDialog(title: string, onClose?: () => void): DialogHandle {
  const body = h("div", { class: "body" });
  const actions = h("div", { class: "actions" });
  const dialog = h("div", { class: "dialog", role: "dialog", "aria-label": title }, h("h2", null, title), body, actions);
  const overlay = h("div", { class: "overlay" }, dialog);
  const close = () => {
    overlay.remove();
    document.removeEventListener("keydown", onKey, true);
    onClose?.();
  };
  const onKey = (event: KeyboardEvent) => {
    if (event.key === "Escape") {
      event.stopPropagation();
      close();
    }
  };
  overlay.addEventListener("mousedown", (event) => {
    if (event.target === overlay) close();
  });
  document.addEventListener("keydown", onKey, true);
  document.body.append(overlay);
  return { close, body, actions };
}

export interface FormDialog {
  title: string;
  body: Node[];
  confirm: string;
  confirmTestid?: string;
  /** Test id of the refusal shown in the dialog. */
  errorTestid?: string;
  disabled?: boolean;
  /** Runs on the primary button; the dialog closes when it resolves, a refusal is shown in the dialog. */
  submit(): Promise<void>;
}

/** A dialog with fields, Cancel and one primary button whose action may fail (the server's refusal is shown). */
export function formDialog(form: FormDialog): DialogHandle & { error: State<Message | null>; submit(): Promise<void> } {
  const dialog = openDialog(form.title);
  const error = state<Message | null>(null);
  const submit = async () => {
    try {
      error.val = null;
      await form.submit();
      dialog.close();
    } catch (problem) {
      error.val = failure(problem, form.errorTestid);
    }
  };
  dialog.body.append(...form.body, messageView(error));
  dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"),
    h("button", { class: "primary", "data-testid": form.confirmTestid, disabled: form.disabled ?? false, onclick: () => void submit() }, form.confirm));
  return { ...dialog, error, submit };
}

/** Ask before something irreversible (restore, delete, enabling power). Resolves true on confirmation. */
export function confirmAction(title: string, text: string, confirmLabel: string, danger = false): Promise<boolean> {
  return new Promise((resolve) => {
    let answered = false;
    const dialog = openDialog(title, () => {
      if (!answered) resolve(false);
    });
    dialog.body.append(h("p", { style: { margin: "0" } }, text));
    const ok = h("button", { class: danger ? "danger solid" : "primary", "data-testid": "confirm" }, confirmLabel);
    ok.addEventListener("click", () => {
      answered = true;
      dialog.close();
      resolve(true);
    });
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), ok);
    ok.focus();
  });
}

/** Format an error for the user: the server's message when it has one. */
export function errorText(error: unknown): string {
  return error instanceof Error ? error.message : String(error);
}

/** Trigger a download of `url` (archives, DCF, backups) without leaving the page. */
export function download(url: string): void {
  const link = h("a", { href: url, download: "" });
  document.body.append(link);
  link.click();
  link.remove();
}

/** Read a file chosen by the user (archive upload, EDS import). */
export function pickFile(accept: string): Promise<File | null> {
  return new Promise((resolve) => {
    const input = h("input", { type: "file", accept, style: { display: "none" } });
    input.addEventListener("change", () => {
      resolve(input.files?.[0] ?? null);
      input.remove();
    });
    document.body.append(input);
    input.click();
  });
}
