#!/usr/bin/python3
"""Writes a ROS 1 bag from an Event Camera Dataset text folder, with Debian's python3-rosbag.

An independent writer for evfs's bag reader tests: the messages are serialised here by hand
from their published definitions (dvs_msgs/EventArray, sensor_msgs/Image), not by evfs.

  write_rosbag.py FOLDER OUT.bag [--compression none|bz2|lz4] [--events_per_message N]
                  [--encoding mono8|mono16|rgb8|bgr8|rgba8|bgra8|yuv422]
                  [--second_events_topic NAME] [--more_encodings ENC,ENC...] [--unindexed]

--second_events_topic also writes the events on a second EventArray topic, recorded after the
first, with every polarity flipped (so a reader shows which topic it read). --more_encodings
also writes the frames in each encoding named, on the topic /camera/ENC/image_raw. --unindexed leaves a
bag as a recording cut short does: the index at its end gone and the bag header's index_pos 0.
"""
import argparse
import hashlib
import struct
import sys

import numpy as np
import rosbag
import rospy
from PIL import Image as PilImage

HEADER_DEF = "uint32 seq\ntime stamp\nstring frame_id"
EVENT_DEF = "uint16 x\nuint16 y\ntime ts\nbool polarity"


def md5(text):
    return hashlib.md5(text.encode()).hexdigest()


# ROS's md5 rule: nested message types are replaced by their own md5 in the parent's text.
HEADER_MD5 = md5(HEADER_DEF)
EVENT_MD5 = md5(EVENT_DEF)
EVENT_ARRAY_MD5 = md5("%s header\nuint32 height\nuint32 width\n%s events" %
                      (HEADER_MD5, EVENT_MD5))
IMAGE_MD5 = md5("%s header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
                "uint32 step\nuint8[] data" % HEADER_MD5)
SEP = "\n" + "=" * 80 + "\n"


class EventArrayType:
    _type = "dvs_msgs/EventArray"
    _md5sum = EVENT_ARRAY_MD5
    _full_text = ("Header header\nuint32 height\nuint32 width\nEvent[] events" + SEP +
                  "MSG: std_msgs/Header\n" + HEADER_DEF + SEP + "MSG: dvs_msgs/Event\n" +
                  EVENT_DEF + "\n")


class ImageType:
    _type = "sensor_msgs/Image"
    _md5sum = IMAGE_MD5
    _full_text = ("Header header\nuint32 height\nuint32 width\nstring encoding\n"
                  "uint8 is_bigendian\nuint32 step\nuint8[] data" + SEP +
                  "MSG: std_msgs/Header\n" + HEADER_DEF + "\n")


def time_pair(t_s):
    ns = int(round(t_s * 1e9))
    return ns // 1000000000, ns % 1000000000


def header(seq, t_s, frame_id=b"camera"):
    sec, nsec = time_pair(t_s)
    return struct.pack("<III", seq, sec, nsec) + struct.pack("<I", len(frame_id)) + frame_id


def event_array(seq, t_s, width, height, ev):
    out = [header(seq, t_s), struct.pack("<III", height, width, len(ev))]
    for t, x, y, p in ev:
        sec, nsec = time_pair(t)
        out.append(struct.pack("<HHIIB", int(x), int(y), sec, nsec, int(p)))
    return b"".join(out)


def pixels(grey, encoding):
    """The grey frame in `encoding`: (bytes, step, is_bigendian)."""
    h, w = grey.shape
    if encoding == "mono8":
        return grey.tobytes(), w, 0
    if encoding == "mono16":  # big-endian, so that the reader's byte order is exercised
        return (grey.astype(">u2") * 257).tobytes(), 2 * w, 1
    if encoding == "yuv422":  # an encoding evfs refuses
        return np.repeat(grey, 2, axis=1).tobytes(), 2 * w, 0
    channels = len(encoding) - 1  # rgb8, bgr8: 3; rgba8, bgra8: 4
    planes = [grey] * 3 + ([np.full_like(grey, 255)] if channels == 4 else [])
    return np.stack(planes, axis=2).tobytes(), channels * w, 0


def image(seq, t_s, grey, encoding="mono8"):
    h, w = grey.shape
    enc = encoding.encode()
    data, step, bigendian = pixels(grey, encoding)
    return (header(seq, t_s) + struct.pack("<II", h, w) + struct.pack("<I", len(enc)) + enc +
            struct.pack("<BI", bigendian, step) + struct.pack("<I", len(data)) + data)


def drop_index(path):
    """Sets the bag header's index_pos to 0 and cuts the file where the index started."""
    with open(path, "r+b") as f:
        data = f.read()
        at = len(b"#ROSBAG V2.0\n")
        header_len = struct.unpack_from("<I", data, at)[0]
        field_at = at + 4
        while field_at < at + 4 + header_len:
            field_len = struct.unpack_from("<I", data, field_at)[0]
            field = data[field_at + 4:field_at + 4 + field_len]
            if field.startswith(b"index_pos="):
                value_at = field_at + 4 + len(b"index_pos=")
                index_pos = struct.unpack_from("<Q", data, value_at)[0]
                f.seek(value_at)
                f.write(struct.pack("<Q", 0))
                f.truncate(index_pos)
                return
            field_at += 4 + field_len
    raise SystemExit("no index_pos in the bag header of " + path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("out")
    ap.add_argument("--compression", default="none", choices=["none", "bz2", "lz4"])
    ap.add_argument("--events_per_message", type=int, default=1000)
    ap.add_argument("--encoding", default="mono8",
                    choices=["mono8", "mono16", "rgb8", "bgr8", "rgba8", "bgra8", "yuv422"])
    ap.add_argument("--second_events_topic", default="")
    ap.add_argument("--more_encodings", default="")
    ap.add_argument("--unindexed", action="store_true")
    args = ap.parse_args()

    frames = []
    with open(args.folder + "/images.txt") as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                t, path = line.split()[:2]
                frames.append((float(t), np.asarray(PilImage.open(args.folder + "/" + path)
                                                    .convert("L"), dtype=np.uint8)))
    height, width = frames[0][1].shape
    events = np.loadtxt(args.folder + "/events.txt", ndmin=2)

    with rosbag.Bag(args.out, "w", compression=args.compression) as bag:
        for i, (t, grey) in enumerate(frames):
            # Receive time deliberately later than the stamp: readers must use the header stamp.
            bag.write("/dvs/image_raw", ("sensor_msgs/Image", image(i, t, grey, args.encoding), IMAGE_MD5,
                                         ImageType), t=rospy.Time.from_sec(t + 0.01), raw=True)
            for encoding in filter(None, args.more_encodings.split(",")):
                bag.write("/camera/%s/image_raw" % encoding,
                          ("sensor_msgs/Image", image(i, t, grey, encoding), IMAGE_MD5, ImageType),
                          t=rospy.Time.from_sec(t + 0.02), raw=True)
        n = args.events_per_message
        for i in range(0, len(events), n):
            chunk = events[i:i + n]
            bag.write("/dvs/events",
                      ("dvs_msgs/EventArray", event_array(i // n, chunk[0][0], width, height,
                                                          chunk), EVENT_ARRAY_MD5,
                       EventArrayType), t=rospy.Time.from_sec(chunk[-1][0] + 0.001), raw=True)
        if args.second_events_topic:
            flipped = events.copy()
            flipped[:, 3] = 1 - flipped[:, 3]
            for i in range(0, len(flipped), n):
                chunk = flipped[i:i + n]
                bag.write(args.second_events_topic,
                          ("dvs_msgs/EventArray", event_array(i // n, chunk[0][0], width, height,
                                                              chunk), EVENT_ARRAY_MD5,
                           EventArrayType), t=rospy.Time.from_sec(chunk[-1][0] + 0.002),
                          raw=True)
    if args.unindexed:
        drop_index(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
