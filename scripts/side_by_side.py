#!/usr/bin/env python3
"""The image work of scripts/side-by-side, with the standard library only
(PNG read and write through zlib), so that it runs wherever tega does.

    side_by_side.py pick DATASET TRUTH CAMERA_OR_EMPTY FRAMES_TXT
        prints "CAMERA WRINKLE_FRAME BLINK_FRAME" (DATASET's held-out frames, ranked by
        TRUTH's ground truth) and writes why to FRAMES_TXT
    side_by_side.py compose DATASET CAMERA FRAME OUT ROW...
        writes OUT/FRAME-{full,eyes,mouth}.png: truth | each row's render
"""

import json
import os
import struct
import sys
import zlib

GAP = 4  # px of black between the panels


def read_png(path):
    """8-bit, non-interlaced grey, RGB or RGBA PNG -> (width, height, channels, rows of bytes)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"side-by-side: {path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        sys.exit(f"side-by-side: {path}: only 8-bit non-interlaced grey, RGB or RGBA PNGs are read")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            left = line[x - channels] if x >= channels else 0
            up = previous[x]
            if kind == 1:
                line[x] = (line[x] + left) & 255
            elif kind == 2:
                line[x] = (line[x] + up) & 255
            elif kind == 3:
                line[x] = (line[x] + (left + up) // 2) & 255
            elif kind == 4:
                upper_left = previous[x - channels] if x >= channels else 0
                p = left + up - upper_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - upper_left)
                line[x] = (line[x] + (left if pa <= pb and pa <= pc else up if pb <= pc else upper_left)) & 255
        rows.append(line)
        previous = line
    return width, height, channels, rows


def rgb_rows(image, background=(0, 0, 0)):
    """RGB rows; RGBA is composited over the background as tega's renders are."""
    width, _, channels, rows = image
    if channels == 3:
        return rows
    out = []
    for line in rows:
        rgb = bytearray(width * 3)
        for x in range(width):
            if channels == 1:
                rgb[3 * x:3 * x + 3] = bytes([line[x]] * 3)
                continue
            a = line[4 * x + 3]
            for c in range(3):
                rgb[3 * x + c] = (line[4 * x + c] * a + background[c] * (255 - a) + 127) // 255
        out.append(rgb)
    return out


def write_png(path, width, rows):
    raw = b"".join(b"\x00" + bytes(line) for line in rows)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, len(rows), 8, 2, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    with open(path + ".part", "wb") as f:
        f.write(png)
    os.replace(path + ".part", path)


def strip(panels, box):
    """Panels (RGB rows) cropped to box (x0, y0, x1, y1), side by side."""
    x0, y0, x1, y1 = box
    gap = bytes(3 * GAP)
    return [gap.join(bytes(p[y][3 * x0:3 * x1]) for p in panels) for y in range(y0, y1)], \
        len(panels) * (x1 - x0) + GAP * (len(panels) - 1)


def project(camera, point):
    K, R, t = camera["K"], camera["R"], camera["t"]
    c = [sum(R[i][j] * point[j] for j in range(3)) + t[i] for i in range(3)]
    return (K[0][0] * c[0] / c[2] + K[0][2], K[1][1] * c[1] / c[2] + K[1][2])


def part_box(points, width, height):
    """Bounding box grown by 40 % of its longer side (eval's close-ups), at least 32 px, in the image."""
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    grow = 0.4 * max(max(xs) - min(xs), max(ys) - min(ys), 32)
    x0, x1 = int(max(0, min(xs) - grow)), int(min(width, max(xs) + grow + 1))
    y0, y1 = int(max(0, min(ys) - grow)), int(min(height, max(ys) + grow + 1))
    return x0, y0, x1, y1


def pick(dataset_dir, truth, camera, frames_txt):
    dataset = json.load(open(os.path.join(dataset_dir, "dataset.json")))
    test_frames = set(dataset["split"]["test"]["frames"])
    camera = camera or dataset["split"]["train"]["cameras"][0]
    wrinkle, blink = (None, -1.0), (None, -1.0)
    for take in sorted({f.rsplit("_", 1)[0] for f in test_frames}):
        frames = json.load(open(os.path.join(truth, "ground_truth", take, "frames.json")))["frames"]
        for f in frames:
            frame_id = f"{take}_{f['index']:06d}"
            if frame_id not in test_frames:
                continue
            wrinkled = sum(f.get("wrinkles", {}).values())
            blinked = f["expression"].get("eyeBlink_L", 0) + f["expression"].get("eyeBlink_R", 0)
            if wrinkled > wrinkle[1]:
                wrinkle = (frame_id, wrinkled)
            if blinked > blink[1] and frame_id != wrinkle[0]:
                blink = (frame_id, blinked)
    if wrinkle[0] is None or blink[0] is None:
        sys.exit(f"side-by-side: {dataset_dir}: the test take has fewer than two frames")
    with open(frames_txt, "w") as f:
        f.write(f"camera {camera}\nwrinkle frame {wrinkle[0]} (wrinkle activations summing to {wrinkle[1]:.2f})\n"
                f"blink frame {blink[0]} (eyeBlink_L + eyeBlink_R = {blink[1]:.2f})\n")
    print(camera, wrinkle[0], blink[0])


def compose(dataset_dir, camera_name, frame, out, rows):
    dataset = json.load(open(os.path.join(dataset_dir, "dataset.json")))
    rig = json.load(open(os.path.join(dataset_dir, "rig.json")))
    camera = next(c for c in rig["cameras"] if c["name"] == camera_name)
    width, height = camera["width"], camera["height"]
    panels = [rgb_rows(read_png(os.path.join(dataset_dir, "images", camera_name, frame + ".png")))]
    for row in rows:
        panels.append(rgb_rows(read_png(os.path.join(out, "renders", row, camera_name, frame + ".png"))))
    lines, strip_width = strip(panels, (0, 0, width, height))
    write_png(os.path.join(out, f"{frame}-full.png"), strip_width, lines)
    landmarks = dataset.get("landmark_vertices", [])
    if len(landmarks) != 68:
        print(f"side-by-side: {dataset_dir}: no 68 landmark vertices, so no close-ups", file=sys.stderr)
        return
    with open(os.path.join(dataset_dir, "meshes", frame + ".bin"), "rb") as f:
        vertices = f.read()
    points = [project(camera, struct.unpack_from("<3f", vertices, 12 * v)) for v in landmarks]
    for part, indices in (("eyes", range(36, 48)), ("mouth", range(48, 68))):
        lines, strip_width = strip(panels, part_box([points[i] for i in indices], width, height))
        write_png(os.path.join(out, f"{frame}-{part}.png"), strip_width, lines)


if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "pick":
        pick(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5])
    elif len(sys.argv) >= 6 and sys.argv[1] == "compose":
        compose(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6:])
    else:
        sys.exit(__doc__)
