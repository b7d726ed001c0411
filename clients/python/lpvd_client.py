#!/usr/bin/env python3
"""lpvd_client.py - a Python client for the lpvd wire protocol, version 1.

Standard library only (socket, struct, json, array). numpy is used when it
is importable (volumes and query answers then come back as float32 arrays);
the ``zstandard`` module is used when importable, otherwise the client asks
the server for ``"compression": "none"`` (the standard library has no zstd)
and decompresses what is zstd whatever it asks (compression "shq", SPEC
R5.16) with the system's libzstd through ctypes.

    from lpvd_client import Client
    with Client("/tmp/lpvd.sock") as c:      # connects and sends HELLO
        c.tick()
        vol = c.get_volume()                 # Volume: cascades, 12 floats per cell
        print(c.query_irradiance([(0, 1, 0)], [(0, 1, 0)]))

The protocol is protocol/SPEC.md; section numbers below refer to it.

This is the module to import: it re-exports every name of the client, whose
code lives in the modules beside it, one job each (copy all five together):

    lpvd_protocol.py  the wire protocol: header, message types, ERROR codes
                      and exceptions, addresses, attachments' compression,
                      the tick plan's passes
    lpvd_volume.py    volumes: decoding (fp16/fp32, XOR deltas, shq, the
                      layout description), Cascade, Volume and the lookups
    lpvd_session.py   Client (one connection to the daemon) and Frame
    lpvd_selftest.py  the self-test and the command line (main)

Run ``python3 lpvd_client.py --self-test ADDRESS`` for a short end-to-end
check against a running daemon (exit status 0 on success), and
``python3 lpvd_client.py --offline-self-test`` for the checks that need none.
"""

import sys

# Every name the client defines, re-exported here under the names it always
# had (``import lpvd_client as lc; lc.MSG``), private helpers included.
from lpvd_protocol import (  # noqa: F401
    ERROR_NAMES, HAVE_ZSTD, HEADER, MAGIC, MSG, PLAN_PASSES, REPLY_BIT, SERVER_BYE, VERSION, LpvdError,
    ProtocolError, _decompress, _default_compression, _parse_address, _zstd, _zstd_decompress, default_address,
    plan_lines, zstd_decoder)
from lpvd_volume import (  # noqa: F401
    HAVE_NUMPY, IV_UNITS, IV_VOXELS_ROLE, LOOKUP_VALUES, LPV_UNITS, MAX_CASCADES, MAX_DISTANCE_SIDE,
    MAX_IRRADIANCE_SIDE, OCTREE_LEVEL_ROLE, PROBES_TECHNIQUE, PROBES_UNSEEN, SH_LOBE0, SH_LOBE1, SHQ_BOUND_DEFAULT,
    SHQ_BOUND_MAX, SHQ_BOUND_MIN, SHQ_COMPRESSION, SHQ_MAGIC, VISIBILITY_CONTENT, VISIBILITY_VALUE_TYPE,
    VOLUME_LAYOUT_VERSION, _F32, _IV_HELD_WEIGHT, _LOBE0, _LOBE1, Cascade, LayoutError, Visibility, Volume, _f32,
    _floats, _is_int, _np, _oct_bilinear, _oct_encode, _xor, iv_irradiance, probes_irradiance, shq_bound_excess,
    shq_cell_distance, shq_cell_magnitude, shq_cells, shq_decode, shq_decode_payload, shq_distances,
    shq_error_bound, shq_payload_max)
from lpvd_session import Client, Frame  # noqa: F401
from lpvd_selftest import (  # noqa: F401
    _minimal_glb, _probe, _probes_reply, _self_test_iv, _self_test_probes, main, offline_self_test, self_test)

__all__ = [
    "Client", "LpvdError", "ProtocolError", "Volume", "Frame",
    "default_address", "MSG", "HAVE_NUMPY", "HAVE_ZSTD",
]


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
