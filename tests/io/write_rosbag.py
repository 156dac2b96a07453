#!/usr/bin/python3
"""Writes a ROS 1 bag from an Event Camera Dataset text folder, with Debian's python3-rosbag.

An independent writer for evfs's bag reader tests: the messages are serialised here by hand
from their published definitions (dvs_msgs/EventArray, sensor_msgs/Image), not by evfs.

  write_rosbag.py FOLDER OUT.bag [--compression none|bz2|lz4] [--events_per_message N]
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


def image(seq, t_s, grey):
    h, w = grey.shape
    enc = b"mono8"
    return (header(seq, t_s) + struct.pack("<II", h, w) + struct.pack("<I", len(enc)) + enc +
            struct.pack("<BI", 0, w) + struct.pack("<I", w * h) + grey.tobytes())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("out")
    ap.add_argument("--compression", default="none", choices=["none", "bz2", "lz4"])
    ap.add_argument("--events_per_message", type=int, default=1000)
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
            bag.write("/dvs/image_raw", ("sensor_msgs/Image", image(i, t, grey), IMAGE_MD5,
                                         ImageType), t=rospy.Time.from_sec(t + 0.01), raw=True)
        n = args.events_per_message
        for i in range(0, len(events), n):
            chunk = events[i:i + n]
            bag.write("/dvs/events",
                      ("dvs_msgs/EventArray", event_array(i // n, chunk[0][0], width, height,
                                                          chunk), EVENT_ARRAY_MD5,
                       EventArrayType), t=rospy.Time.from_sec(chunk[-1][0] + 0.001), raw=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
