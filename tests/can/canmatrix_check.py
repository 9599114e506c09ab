#!/usr/bin/env python3
"""Independent check of config/sonocomp.dbc: Debian's python3-canmatrix loads the DBC and
decodes every frame the core codec encoded (printed by sc_canproto_dump). For each frame:
- canmatrix knows the id, its FD-ness and its length;
- every signal canmatrix decodes equals the core's physical value (within 1e-6 relative:
  the core computes in float32);
- the core's physical values, scaled to raw with the DBC's factor/offset and packed by
  canmatrix, give exactly the same payload bytes;
- the E2E CRC byte equals CRC-8 SAE J1850 (poly 0x1D, start 0x00, xor 0x00) computed here
  over data ID (= CAN id, from the DBC attribute E2E_DataID) low, high byte and bytes 1..n-1
  (every message but the commands' cryptographic PDUs CmdAuth*, which have no E2E header).
Exit 77 (ctest SKIP) when canmatrix is not installed."""
import decimal
import subprocess
import sys

try:
    import canmatrix.formats
except ImportError:
    print("SKIP: python3-canmatrix is not installed (apt-get install -y python3-canmatrix)")
    sys.exit(77)


def crc8_j1850(data, crc=0):
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def main():
    dbc, dump = sys.argv[1], sys.argv[2]
    dbs = canmatrix.formats.loadp(dbc)
    db = dbs[next(iter(dbs))]
    out = subprocess.run([dump], check=True, capture_output=True, text=True).stdout
    frames = 0
    failures = []
    for line in out.splitlines():
        parts = line.split()
        name, can_id, fd, payload = parts[0], int(parts[1], 16), parts[2] == "1", parts[3]
        core_phys = [float(v) for v in parts[4:]]
        data = bytes.fromhex(payload)
        fr = db.frame_by_id(canmatrix.ArbitrationId(can_id))
        if fr is None:
            failures.append("0x%X: not in the DBC" % can_id)
            continue
        if fr.name != name or fr.size != len(data) or bool(fr.is_fd) != fd:
            failures.append("0x%X: DBC says %s size %d fd %s, core sent %s size %d fd %s"
                            % (can_id, fr.name, fr.size, fr.is_fd, name, len(data), fd))
            continue
        decoded = fr.decode(bytearray(data))
        if len(decoded) != len(core_phys):
            failures.append("%s: DBC has %d signals, core %d" % (name, len(decoded), len(core_phys)))
            continue
        values = {}
        for (sig_name, d), core in zip(decoded.items(), core_phys):
            phys = float(d.phys_value)
            sig = d.signal
            # the core's physical value back to raw with the DBC's scaling (canmatrix's
            # Frame.encode takes raw values; its phys2raw truncates, so round here)
            values[sig_name] = int(round((decimal.Decimal(repr(core)) - sig.offset) / sig.factor))
            if abs(phys - core) > 1e-6 * max(1.0, abs(phys)):
                failures.append("%s.%s: canmatrix %r, core %r (payload %s)"
                                % (name, sig_name, phys, core, payload))
        again = bytes(fr.encode(values))
        if again != data:
            failures.append("%s: canmatrix encodes the core's values as %s, core sent %s"
                            % (name, again.hex().upper(), payload))
        has_e2e = any(s.name == "E2E_CRC" for s in fr.signals)
        if has_e2e:
            data_id = int(fr.attributes.get("E2E_DataID", -1))
            if data_id != can_id:
                failures.append("%s: E2E_DataID %d != id" % (name, data_id))
            crc = crc8_j1850(bytes([data_id & 0xFF, data_id >> 8]) + data[1:])
            if crc != data[0]:
                failures.append("%s: E2E CRC 0x%02X, expected 0x%02X" % (name, data[0], crc))
        elif "E2E_DataID" in fr.attributes or not name.startswith("CmdAuth"):
            # only the commands' cryptographic PDUs go without an E2E header (their MAC
            # protects them)
            failures.append("%s: no E2E header" % name)
        frames += 1
    for f in failures[:30]:
        print("FAIL", f)
    print("canmatrix %s checked %d frames of %d messages: %d failures"
          % (getattr(canmatrix, "__version__", "?"), frames, len(db.frames), len(failures)))
    return 1 if failures or frames == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
