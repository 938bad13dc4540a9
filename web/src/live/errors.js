// Web Serial's errors, worded as what to do about them.

/** The browsers that have Web Serial. */
export const SERIAL_BROWSERS = 'Chrome, Edge or Firefox 151 and later';

/** The note a browser without Web Serial shows in place of the live mode. */
export function noSerialNote() {
  return `This browser cannot open serial ports (Web Serial). Live mode needs ${SERIAL_BROWSERS} ` +
    'on a desktop computer; the Files tab works here: open a recording made with hwfoc record.';
}

/** Whether the page can open serial ports. */
export function hasWebSerial(nav = globalThis.navigator) {
  return Boolean(nav && nav.serial && typeof nav.serial.requestPort === 'function');
}

/** Linux's group whose members may open serial devices, and the fix. */
const DIALOUT = 'on Linux your user must be in the dialout group: ' +
  'sudo usermod -aG dialout $USER, then log out and in again';

/**
 * The line a person reads for an error of `requestPort` or `open` (`what`: 'choose' or
 * 'open'), about the port named `name`.
 */
export function explain(error, what, name = 'the port') {
  const kind = error?.name ?? '';
  if (what === 'choose') {
    if (kind === 'NotFoundError') return 'No port was chosen: click "Add port" and pick the adapter in the list (plug it in first if it is not there).';
    if (kind === 'SecurityError') return `Serial ports are blocked on this page (${error.message}): open it from https:// or http://localhost, not from a file or an embedded frame.`;
    return `Could not choose a port: ${error?.message ?? error}.`;
  }
  if (kind === 'InvalidStateError') return `${name} is already open in this page.`;
  if (kind === 'NetworkError' || kind === 'NotReadableError' || kind === 'NotAllowedError') {
    return `${name} could not be opened: another program is using it (close hwfoc monitor, a terminal or ` +
      `a configurator, or another tab), or ${DIALOUT}.`;
  }
  return `${name} could not be opened: ${error?.message ?? error}.`;
}

/** What a port that was unplugged shows until it comes back. */
export function unpluggedNote(name) {
  return `${name} was unplugged: plug it back in and it resumes by itself.`;
}
