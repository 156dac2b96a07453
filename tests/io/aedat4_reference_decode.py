#!/usr/bin/env python3
"""An independent decoding of an AEDAT 4.0 file, for tests/io/aedat4_test.cc.

Written from the format description (docs.inivation.com, "AEDAT 4.0") with Debian's
python3-lz4, python3-zstandard and python3-flatbuffers, sharing no code with evfs' reader: the
packets are walked one after the other from the header (the file data table is not used for
reading, only counted), the flatbuffers are read with flatbuffers.table.Table by field slot,
and the XML stream description with xml.etree.

    aedat4_reference_decode.py FILE

prints "key values..." lines:
    compression N           IOHeader.compression
    sensor W H              sizeX, sizeY of the first EVTS stream (else FRME stream)
    ts_offset_us N          its tsOffset (0 when absent)
    packets N               packets of that EVTS stream holding events
    events N                events, and of them
    positive N              with polarity ON
    first T X Y P           the first event (T in microseconds, P 1 ON / 0 OFF)
    last T X Y P            the last event
    sum_dt N                the sum over all events of their time after the first event's (us)
    sum_x N, sum_y N        the sums of their x and of their y
    fnv1a64 HEX             FNV-1a (64 bits) over every event as int64 t, uint16 x, uint16 y,
                            uint8 p, little-endian
    frames N                frames of the first FRME stream, then one line each:
    frame I T SOE EOE W H FORMAT FNV   times in microseconds, FNV-1a of the pixel bytes
    pixel_sum I N           the sum of frame I's pixel bytes
    table_entries N         entries of the file data table (-1 without one)
Exit status 3 when a module is missing (the test skips), 1 for a file it cannot decode.
"""
import struct
import sys
import xml.etree.ElementTree as ElementTree

try:
    import lz4.frame
    from flatbuffers import encode
    from flatbuffers import number_types
    from flatbuffers.table import Table
except ImportError as error:
    print(f"missing module: {error}", file=sys.stderr)
    sys.exit(3)
try:
    import zstandard
except ImportError:
    zstandard = None

VERSION_LINE = b"#!AER-DAT4.0\r\n"
FNV_OFFSET = 0xCBF29CE484222325
FNV_PRIME = 0x100000001B3
MASK64 = (1 << 64) - 1


def fnv1a64(data, h=FNV_OFFSET):
    for byte in data:
        h = ((h ^ byte) * FNV_PRIME) & MASK64
    return h


def decompress(compression, body):
    if compression == 0:
        return body
    if compression in (1, 2):
        return lz4.frame.decompress(body)
    if compression in (3, 4):
        if zstandard is None:
            print("missing module: zstandard", file=sys.stderr)
            sys.exit(3)
        return zstandard.ZstdDecompressor().decompress(body)
    raise ValueError(f"unknown compression {compression}")


def root_table(size_prefixed, identifier):
    """The root table of a size-prefixed flatbuffer, checking its size and identifier."""
    (size,) = struct.unpack_from("<I", size_prefixed, 0)
    if size != len(size_prefixed) - 4:
        raise ValueError("size prefix disagrees with the buffer")
    buf = bytearray(size_prefixed[4:])
    if identifier is not None and bytes(buf[4:8]) != identifier:
        raise ValueError(f"expected identifier {identifier}, found {bytes(buf[4:8])}")
    root = encode.Get(number_types.UOffsetTFlags.packer_type, buf, 0)
    return Table(buf, root)


def scalar(table, slot, flags, default=0):
    """Field `slot` (0-based, as declared in the schema) of `table`."""
    offset = table.Offset(4 + 2 * slot)
    return table.Get(flags, table.Pos + offset) if offset else default


def vector(table, slot):
    """(start, length) of the vector in field `slot`, or (0, 0)."""
    offset = table.Offset(4 + 2 * slot)
    if not offset:
        return 0, 0
    return table.Vector(offset), table.VectorLen(offset)


def streams(info_xml):
    """{stream id: (type, sizeX, sizeY, tsOffset)} from the stream description."""
    root = ElementTree.fromstring(info_xml)
    out_info = next(n for n in root.findall("node") if n.get("name") == "outInfo")
    result = {}
    for node in out_info.findall("node"):
        attrs = {a.get("key"): (a.text or "") for a in node.findall("attr")}
        info = next((n for n in node.findall("node") if n.get("name") == "info"), None)
        info_attrs = {a.get("key"): (a.text or "") for a in info.findall("attr")} if info else {}
        result[int(node.get("name"))] = (
            attrs.get("typeIdentifier"),
            int(info_attrs.get("sizeX", 0)),
            int(info_attrs.get("sizeY", 0)),
            int(info_attrs.get("tsOffset", 0)),
        )
    return result


def main(path):
    data = open(path, "rb").read()
    if not data.startswith(VERSION_LINE):
        raise ValueError("not an AEDAT 4.0 file")
    position = len(VERSION_LINE)
    (header_size,) = struct.unpack_from("<I", data, position)
    header = root_table(data[position : position + 4 + header_size], b"IOHE")
    position += 4 + header_size
    compression = scalar(header, 0, number_types.Int32Flags, 0)
    table_position = scalar(header, 1, number_types.Int64Flags, -1)
    info_offset = header.Offset(8)
    info_xml = header.String(header.Pos + info_offset).decode("utf-8")
    described = streams(info_xml)
    events_id = min((i for i, s in described.items() if s[0] == "EVTS"), default=None)
    frames_id = min((i for i, s in described.items() if s[0] == "FRME"), default=None)
    main_id = events_id if events_id is not None else frames_id
    _, size_x, size_y, ts_offset = described[main_id]

    end = table_position if table_position >= 0 else len(data)
    packets = events = positive = sum_dt = sum_x = sum_y = 0
    digest = FNV_OFFSET
    first = last = None
    frame_lines = []
    pixel_sums = []
    while position < end:
        stream_id, size = struct.unpack_from("<ii", data, position)
        body = data[position + 8 : position + 8 + size]
        if len(body) != size:
            raise ValueError("truncated packet")
        position += 8 + size
        if stream_id == events_id:
            packet = root_table(decompress(compression, body), b"EVTS")
            start, length = vector(packet, 0)
            packets += 1 if length else 0
            for k in range(length):
                t, x, y, p = struct.unpack_from("<qhhB", packet.Bytes, start + 16 * k)
                p = 1 if p else 0
                event = (t, x, y, p)
                first = first or event
                last = event
                events += 1
                positive += p
                sum_dt += t - first[0]
                sum_x += x
                sum_y += y
                digest = fnv1a64(struct.pack("<qHHB", t, x, y, p), digest)
        elif stream_id == frames_id:
            frame = root_table(decompress(compression, body), b"FRME")
            start, length = vector(frame, 10)
            pixels = bytes(frame.Bytes[start : start + length])
            pixel_sums.append(sum(pixels))
            frame_lines.append(
                " ".join(
                    str(v)
                    for v in (
                        scalar(frame, 0, number_types.Int64Flags),
                        scalar(frame, 3, number_types.Int64Flags),
                        scalar(frame, 4, number_types.Int64Flags),
                        scalar(frame, 6, number_types.Int16Flags),
                        scalar(frame, 7, number_types.Int16Flags),
                        scalar(frame, 5, number_types.Int8Flags),
                        f"{fnv1a64(pixels):016x}",
                    )
                )
            )
    if table_position >= 0:
        table = root_table(decompress(compression, data[table_position:]), b"FTAB")
        table_entries = vector(table, 0)[1]
    else:
        table_entries = -1

    print(f"compression {compression}")
    print(f"sensor {size_x} {size_y}")
    print(f"ts_offset_us {ts_offset}")
    print(f"packets {packets}")
    print(f"events {events}")
    print(f"positive {positive}")
    if first is not None:
        print("first %d %d %d %d" % first)
        print("last %d %d %d %d" % last)
    print(f"sum_dt {sum_dt}")
    print(f"sum_x {sum_x}")
    print(f"sum_y {sum_y}")
    print(f"fnv1a64 {digest:016x}")
    print(f"frames {len(frame_lines)}")
    for i, line in enumerate(frame_lines):
        print(f"frame {i} {line}")
    for i, pixel_sum in enumerate(pixel_sums):
        print(f"pixel_sum {i} {pixel_sum}")
    print(f"table_entries {table_entries}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    try:
        main(sys.argv[1])
    except (ValueError, struct.error, KeyError, StopIteration, RuntimeError) as error:
        print(f"cannot decode {sys.argv[1]}: {error}", file=sys.stderr)
        sys.exit(1)
