// Where the tests find the hwfoc binary.
import { existsSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const repo = fileURLToPath(new URL('../../../', import.meta.url));

/** The hwfoc binary: $HWFOC_BIN, else the workspace's debug or release build; null if none. */
export function hwfocBin() {
  const candidates = [process.env.HWFOC_BIN, `${repo}target/debug/hwfoc`, `${repo}target/release/hwfoc`];
  return candidates.find((p) => p && existsSync(p)) ?? null;
}
