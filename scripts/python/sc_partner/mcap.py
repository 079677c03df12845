"""A minimal reader of the partition's MCAP recordings (standard library only).

The recorder (``libs/ground/src/mcap/``) writes ``recording.mcap``: one
channel per service, named as the service, every message JSON-encoded (NaN and the
infinities as ``null``), in LZ4-compressed chunks. This module reads exactly that:
the MCAP records (https://mcap.dev/spec) and the LZ4 frame format, without the
``mcap`` and ``lz4`` packages, so that the partner SDK keeps needing only iceoryx2 and
numpy. Uncompressed chunks and chunks outside any compression are read as well; other
compressions (zstd) raise ``ValueError``. Records other than channels, messages and
chunks (the header, schemas, the run's ``Metadata`` record, the summary section's
indexes and statistics, the footer) are skipped; ``scripts/mcap_check.py`` checks on a
real recording that this reader yields exactly the messages the ``mcap`` package reads.
"""

import json
import struct

MAGIC = b"\x89MCAP0\r\n"
_OP_CHANNEL = 0x04
_OP_MESSAGE = 0x05
_OP_CHUNK = 0x06
_LZ4_FRAME_MAGIC = 0x184D2204


def lz4_block(src, out):
    """Decodes one LZ4 block `src` (bytes), appending to `out` (a bytearray that holds
    the frame's earlier output, which matches of linked blocks may refer to)."""
    i, n = 0, len(src)
    while i < n:
        token = src[i]
        i += 1
        literals = token >> 4
        if literals == 15:
            while True:
                b = src[i]
                i += 1
                literals += b
                if b != 255:
                    break
        out += src[i : i + literals]
        i += literals
        if i >= n:  # the last sequence has literals only
            break
        offset = src[i] | (src[i + 1] << 8)
        i += 2
        if offset == 0 or offset > len(out):
            raise ValueError(f"LZ4: match offset {offset} outside the {len(out)} bytes decoded")
        length = token & 15
        if length == 15:
            while True:
                b = src[i]
                i += 1
                length += b
                if b != 255:
                    break
        length += 4
        start = len(out) - offset
        if offset >= length:
            out += out[start : start + length]
        else:  # overlapping: the last `offset` bytes repeat
            pattern = bytes(out[start:])
            out += (pattern * (length // offset + 1))[:length]


def lz4_frame(data):
    """The content of the LZ4 frame `data` (checksums are not verified)."""
    if len(data) < 7 or struct.unpack_from("<I", data, 0)[0] != _LZ4_FRAME_MAGIC:
        raise ValueError("not an LZ4 frame")
    flg = data[4]
    if flg >> 6 != 1:
        raise ValueError(f"LZ4 frame version {flg >> 6}")
    i = 6  # FLG, BD
    if flg & 0x08:  # content size
        i += 8
    if flg & 0x01:  # dictionary id
        i += 4
    i += 1  # header checksum
    block_checksum = bool(flg & 0x10)
    out = bytearray()
    while True:
        (size,) = struct.unpack_from("<I", data, i)
        i += 4
        if size == 0:
            break
        raw = bool(size & 0x80000000)
        size &= 0x7FFFFFFF
        block = data[i : i + size]
        i += size + (4 if block_checksum else 0)
        if raw:
            out += block
        else:
            lz4_block(block, out)
    return bytes(out)


def _string(buf, i):
    (n,) = struct.unpack_from("<I", buf, i)
    return buf[i + 4 : i + 4 + n].decode(), i + 4 + n


def _records(buf, i, end):
    while i + 9 <= end:
        op = buf[i]
        (n,) = struct.unpack_from("<Q", buf, i + 1)
        yield op, buf[i + 9 : i + 9 + n]
        i += 9 + n


def _chunk_records(content):
    i = 8 + 8 + 8 + 4  # start time, end time, uncompressed size, crc
    compression, i = _string(content, i)
    (n,) = struct.unpack_from("<Q", content, i)
    data = content[i + 8 : i + 8 + n]
    if compression == "lz4":
        data = lz4_frame(data)
    elif compression != "":
        raise ValueError(f"MCAP chunk compression {compression!r}: only lz4 and none are supported")
    return _records(data, 0, len(data))


def messages(path, topics=None):
    """Yields (topic, log_time_ns, decoded JSON message) of every message in the MCAP
    file `path`, in file order; only `topics` (a set of channel topics) if given."""
    with open(path, "rb") as f:
        buf = f.read()
    if not buf.startswith(MAGIC):
        raise ValueError(f"{path}: not an MCAP file")
    channels = {}

    def walk(records):
        for op, content in records:
            if op == _OP_CHUNK:
                yield from walk(_chunk_records(content))
            elif op == _OP_CHANNEL:
                channel_id = struct.unpack_from("<H", content, 0)[0]
                topic, i = _string(content, 4)
                encoding, _ = _string(content, i)
                channels[channel_id] = (topic, encoding)
            elif op == _OP_MESSAGE:
                channel_id, _seq, log_time, _pub = struct.unpack_from("<HIQQ", content, 0)
                topic, encoding = channels[channel_id]
                if topics is not None and topic not in topics:
                    continue
                if encoding != "json":
                    raise ValueError(f"{path}: channel {topic} is {encoding!r}, not json")
                yield topic, log_time, json.loads(content[22:])

    yield from walk(_records(buf, len(MAGIC), len(buf)))
