#!/usr/bin/python3
"""Writes a large synthetic ROS 1 bag for the memory figures of BENCHMARKS.md ("A large ROS bag").

  write_large_rosbag.py OUT.bag [--frames N] [--events_per_frame N] [--compression none|lz4]

A 346x260 sensor (DAVIS346): a grey ramp that shifts by one pixel per frame, recorded at 50 fps,
and between two frames `events_per_frame` events at random pixels and times (seeded), in arrays
of 1000 as the DAVIS driver publishes them. The defaults give about 620 MB: 4000 frames
(360 MB of mono8 pixels) and 20 million events (260 MB). The messages are serialised by
tests/io/write_rosbag.py's functions (the published definitions).
"""
import argparse
import os
import sys

import numpy as np
import rosbag
import rospy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "io"))
import write_rosbag as wr  # noqa: E402

WIDTH, HEIGHT = 346, 260
FPS = 50.0
EVENTS_PER_MESSAGE = 1000
EVENT_DTYPE = np.dtype([("x", "<u2"), ("y", "<u2"), ("sec", "<u4"), ("nsec", "<u4"), ("p", "u1")])


def event_array(seq, t_ns, x, y, p):
    """A dvs_msgs/EventArray of the events at times t_ns (int64 ns), pixels (x, y), polarity p."""
    events = np.empty(len(t_ns), dtype=EVENT_DTYPE)
    events["x"], events["y"], events["p"] = x, y, p
    events["sec"], events["nsec"] = t_ns // 1000000000, t_ns % 1000000000
    return (wr.header(seq, t_ns[0] * 1e-9) + np.array([HEIGHT, WIDTH, len(t_ns)], "<u4").tobytes() +
            events.tobytes())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--frames", type=int, default=4000)
    ap.add_argument("--events_per_frame", type=int, default=5000)
    ap.add_argument("--compression", default="none", choices=["none", "lz4"])
    args = ap.parse_args()

    rng = np.random.default_rng(7)
    ramp = (np.arange(WIDTH * 2) % 256).astype(np.uint8)
    start_ns = 1000000000
    period_ns = int(1e9 / FPS)
    seq = 0
    with rosbag.Bag(args.out, "w", compression=args.compression) as bag:
        for i in range(args.frames):
            t_ns = start_ns + i * period_ns
            grey = np.tile(ramp[i % WIDTH:i % WIDTH + WIDTH], (HEIGHT, 1))
            bag.write("/dvs/image_raw", ("sensor_msgs/Image", wr.image(i, t_ns * 1e-9, grey),
                                         wr.IMAGE_MD5, wr.ImageType),
                      t=rospy.Time.from_sec(t_ns * 1e-9 + 0.001), raw=True)
            if i + 1 == args.frames:
                break
            n = args.events_per_frame
            times = np.sort(rng.integers(t_ns, t_ns + period_ns, n))
            x = rng.integers(0, WIDTH, n)
            y = rng.integers(0, HEIGHT, n)
            p = rng.integers(0, 2, n)
            for k in range(0, n, EVENTS_PER_MESSAGE):
                s = slice(k, k + EVENTS_PER_MESSAGE)
                bag.write("/dvs/events",
                          ("dvs_msgs/EventArray", event_array(seq, times[s], x[s], y[s], p[s]),
                           wr.EVENT_ARRAY_MD5, wr.EventArrayType),
                          t=rospy.Time.from_sec(times[s][-1] * 1e-9 + 0.001), raw=True)
                seq += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
