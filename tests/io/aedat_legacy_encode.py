#!/usr/bin/env python3
"""Writes a data folder (events.txt, images.txt, 8-bit grey PNGs) as AEDAT 2.0 and 3.1 files.

An encoder independent of evfs, from the published layouts only (iniVation's "AEDAT file
formats", jAER's DAVIS address layout, libcaer's polarity and frame events, v2e's AEDat2Output),
with the standard library alone. io_test reads its files back and compares them with the folder.

    aedat_legacy_encode.py FOLDER OUT_DIR

writes into OUT_DIR:
  us/               the folder with its event times rounded to the microsecond (the resolution of
                    both formats), images.txt and the images linked: what the files must read as
  davis240.aedat2   jAER AEDAT 2.0 (header naming a DAVIS240C): DVS events and global-shutter APS
                    frames, each pixel's reset read then its signal read, reset - signal equal to
                    the 8-bit value scaled to the 10-bit ADC; a special event and an IMU sample
                    are mixed in (readers skip them). Each frame's reset reads lie 1 us before its
                    images.txt time and its signal reads 1 us after.
  v2e346.aedat2     v2e's AEDAT 2.0 output for a DAVIS346 (its header, which names no chip; x
                    and y flipped), DVS events only, shifted by (+100, +80) so that the largest
                    address says DAVIS346
  davis240.aedat3   cAER AEDAT 3.1: polarity packets (some with unfilled capacity and an invalid
                    event), an IMU packet, one frame packet per image with 16-bit pixels
                    (value * 257) and a zero-length exposure at the images.txt time
"""
import os
import struct
import sys
import zlib

WIDTH, HEIGHT = 240, 180
V2E_WIDTH, V2E_HEIGHT, V2E_SHIFT_X, V2E_SHIFT_Y = 346, 260, 100, 80


def decimal_to_micro(text):
    """Decimal seconds as a string to integer microseconds, rounded half up, without floats."""
    whole, _, fraction = text.partition(".")
    fraction = (fraction + "0" * 9)[:9]
    nanoseconds = int(whole) * 10**9 + int(fraction)
    return (nanoseconds + 500) // 1000


def read_png_grey8(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    offset, idat, width = 8, b"", 0
    while offset < len(data):
        length, kind = struct.unpack(">I4s", data[offset:offset + 8])
        body = data[offset + 8:offset + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, colour, interlace) == (8, 0, 0), "8-bit grey, not interlaced"
        elif kind == b"IDAT":
            idat += body
        offset += 12 + length
    raw = zlib.decompress(idat)
    rows, previous = [], bytearray(width)
    for row in range(height):
        line = raw[row * (width + 1):(row + 1) * (width + 1)]
        kind, out = line[0], bytearray(line[1:])
        for i in range(width):
            left = out[i - 1] if i > 0 else 0
            up, up_left = previous[i], previous[i - 1] if i > 0 else 0
            if kind == 1:
                out[i] = (out[i] + left) & 255
            elif kind == 2:
                out[i] = (out[i] + up) & 255
            elif kind == 3:
                out[i] = (out[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - up_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - up_left)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else up_left)
                out[i] = (out[i] + predictor) & 255
        rows.append(bytes(out))
        previous = out
    return width, height, rows


def read_folder(folder):
    events = []
    for line in open(os.path.join(folder, "events.txt")):
        fields = line.split()
        if fields:
            events.append((decimal_to_micro(fields[0]), int(fields[1]), int(fields[2]),
                           int(fields[3])))
    frames = []
    for line in open(os.path.join(folder, "images.txt")):
        fields = line.split()
        if fields:
            width, height, rows = read_png_grey8(os.path.join(folder, fields[1]))
            assert (width, height) == (WIDTH, HEIGHT)
            frames.append((decimal_to_micro(fields[0]), fields[1], rows))
    return events, frames


def write_microsecond_folder(folder, out, events, frames):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "events.txt"), "w") as f:
        for t, x, y, p in events:
            f.write("%d.%06d %d %d %d\n" % (t // 10**6, t % 10**6, x, y, p))
    with open(os.path.join(out, "images.txt"), "w") as f:
        for t, path, _ in frames:
            f.write("%d.%06d %s\n" % (t // 10**6, t % 10**6, path))
    link = os.path.join(out, "images")
    if not os.path.exists(link):
        os.symlink(os.path.abspath(os.path.join(folder, "images")), link)


def davis_address(x, y, width, height):
    """jAER's DAVIS address bits of pixel (x, y) counted from the top left: x from the right
    column at bit 12, y from the bottom row at bit 22."""
    return ((height - 1 - y) << 22) | ((width - 1 - x) << 12)


def write_aedat2(path, events, frames):
    aps, signal, imu, special = 1 << 31, 1 << 10, 3 << 10, 1 << 10
    records = []  # (time, order, address); order keeps a frame's reads after the events before
    for t, x, y, p in events:
        records.append((t, 1, davis_address(x, y, WIDTH, HEIGHT) | (p << 11)))
    for t, _, rows in frames:
        for y in range(HEIGHT):
            for x in range(WIDTH):
                difference = (rows[y][x] * 1023 + 127) // 255
                reset = min(1023, difference + 300 + (7 * x + 3 * y) % 50)
                address = aps | davis_address(x, y, WIDTH, HEIGHT)
                records.append((t - 1, 2, address | reset))
                records.append((t + 1, 3, address | signal | (reset - difference)))
    first = events[0][0]
    records.append((first, 0, davis_address(5, 5, WIDTH, HEIGHT) | special))
    records.append((first, 0, aps | imu | 0x155))
    records.sort(key=lambda r: (r[0], r[1]))  # stable: raster order within a frame's reads
    with open(path, "wb") as f:
        f.write(b"#!AER-DAT2.0\r\n")
        f.write(b"# This is a raw AE data file - do not edit\r\n")
        f.write(b"# Data format is int32 address, int32 timestamp (8 bytes total)\r\n")
        f.write(b"# Timestamps tick is 1 us\r\n")
        f.write(b"# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n")
        f.write(b"# End of ASCII Header\r\n")
        f.write(b"".join(struct.pack(">Ii", address, t) for t, _, address in records))


def write_v2e_aedat2(path, events):
    with open(path, "wb") as f:
        for line in ("#!AER-DAT2.0",
                     "# This is a raw AE data file created by AEDat2Output in v2e",
                     "# Data format is int32 address, int32 timestamp (8 bytes total), "
                     "repeated for each event",
                     "# Timestamps tick is 1 us",
                     "# Creation time: 07:35AM November 28 2026",
                     "# User name: evfs"):
            f.write((line + "\r\n").encode())
        for t, x, y, p in events:
            x = (V2E_WIDTH - 1) - (x + V2E_SHIFT_X)
            y = (V2E_HEIGHT - 1) - (y + V2E_SHIFT_Y)
            f.write(struct.pack(">ii", (x << 12) | (y << 22) | (p << 11), t))


def packet(event_type, event_size, overflow, events, capacity):
    header = struct.pack("<hhiiiiii", event_type, 1, event_size, 4, overflow, capacity,
                         len(events), len(events))
    return header + b"".join(events) + b"\0" * (event_size * (capacity - len(events)))


def write_aedat3(path, events, frames):
    per_packet = 3000
    chunks = []  # (time of the first content, bytes)
    for start in range(0, len(events), per_packet):
        chunk = events[start:start + per_packet]
        overflow = chunk[0][0] >> 31
        assert all(t >> 31 == overflow for t, _, _, _ in chunk)
        encoded = [struct.pack("<Ii", (x << 17) | (y << 2) | (p << 1) | 1, t & 0x7fffffff)
                   for t, x, y, p in chunk]
        # An invalid event (coordinates outside any sensor) between two valid ones.
        encoded.insert(1, struct.pack("<Ii", (0x7fff << 17) | (0x7fff << 2), chunk[0][0]))
        capacity = len(encoded) + (17 if (start // per_packet) % 2 else 0)
        chunks.append((chunk[0][0], 1, packet(1, 8, overflow, encoded, capacity)))
    imu = struct.pack("<I", 1) + b"\0" * 32
    chunks.append((events[0][0], 0, packet(3, 36, 0, [imu, imu], 2)))
    for t, _, rows in frames:
        pixels = b"".join(struct.pack("<%dH" % WIDTH, *[v * 257 for v in row]) for row in rows)
        frame = struct.pack("<Iiiiiiiii", 1 | (1 << 1), t, t, t, t, WIDTH, HEIGHT, 0, 0) + pixels
        chunks.append((t, 2, packet(2, len(frame), t >> 31, [frame], 1)))
    chunks.sort(key=lambda c: (c[0], c[1]))
    with open(path, "wb") as f:
        f.write(b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n"
                b"#Start-Time: 2026-11-28 07:35:00 (TZ+0000)\r\n#!END-HEADER\r\n")
        for _, _, body in chunks:
            f.write(body)


def main():
    folder, out = sys.argv[1], sys.argv[2]
    events, frames = read_folder(folder)
    os.makedirs(out, exist_ok=True)
    write_microsecond_folder(folder, os.path.join(out, "us"), events, frames)
    write_aedat2(os.path.join(out, "davis240.aedat2"), events, frames)
    write_v2e_aedat2(os.path.join(out, "v2e346.aedat2"), events)
    write_aedat3(os.path.join(out, "davis240.aedat3"), events, frames)


if __name__ == "__main__":
    main()
