#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz harnesses (corpus/<harness>/).

Seeds are small on purpose: a few valid files of each kind (so that the
fuzzer starts from the parsers' main paths) and one of every hostile class the
readers must refuse quickly: a bare header, counts in the billions, truncated
face lists, lying element or triangle counts, coordinates near the float
limit, NaN and infinity. Run it after changing a seed; the output is
committed, and libFuzzer adds what it finds to its own working corpus, not to
these folders.
"""
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))

# A tetrahedron: 4 vertices, 4 faces.
V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def off_ascii(vertices=V, faces=F, header="OFF"):
    lines = [header, f"{len(vertices)} {len(faces)} 0"]
    lines += [" ".join(str(c) for c in v) for v in vertices]
    lines += ["3 " + " ".join(str(i) for i in f) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def off_binary():
    out = b"OFF BINARY\n" + struct.pack(">iii", len(V), len(F), 0)
    for v in V:
        out += struct.pack(">fff", *v)
    for f in F:
        out += struct.pack(">iiii", 3, *f) + struct.pack(">i", 0)
    return out


def obj(vertices=V, faces=F):
    lines = ["# tetrahedron", "o tetra"] + ["v %s %s %s" % v for v in vertices]
    lines += ["f %d %d %d" % tuple(i + 1 for i in f) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def ply_ascii(nv=None, nf=None):
    nv = len(V) if nv is None else nv
    nf = len(F) if nf is None else nf
    head = ("ply\nformat ascii 1.0\ncomment tiny\nelement vertex %d\nproperty float x\n"
            "property float y\nproperty float z\nelement face %d\n"
            "property list uchar int vertex_indices\nend_header\n") % (nv, nf)
    body = "".join("%s %s %s\n" % v for v in V) + "".join("3 %d %d %d\n" % f for f in F)
    return (head + body).encode()


def ply_binary(fmt="binary_little_endian", order="<", nv=None, nf=None):
    nv = len(V) if nv is None else nv
    nf = len(F) if nf is None else nf
    head = ("ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list uchar uint vertex_indices\n"
            "end_header\n") % (fmt, nv, nf)
    body = b"".join(struct.pack(order + "fff", *v) for v in V)
    body += b"".join(struct.pack(order + "B3I", 3, *f) for f in F)
    return head.encode() + body


def stl_ascii():
    out = "solid tetra\n"
    for f in F:
        out += " facet normal 0 0 0\n  outer loop\n"
        out += "".join("   vertex %s %s %s\n" % V[i] for i in f)
        out += "  endloop\n endfacet\n"
    return (out + "endsolid tetra\n").encode()


def stl_binary(count=None, header=b"binary tetra"):
    out = header.ljust(80, b" ") + struct.pack("<I", len(F) if count is None else count)
    for f in F:
        out += struct.pack("<3f", 0, 0, 0)
        for i in f:
            out += struct.pack("<3f", *V[i])
        out += b"\0\0"
    return out


BIG = 3.4e38  # near FLT_MAX: finite, but the area overflows to infinity
MESH_SEEDS = {
    "off": {
        "tetra.off": off_ascii(),
        "comments_before_header.off": b"# made by hand\n\n# second comment\n" + off_ascii(),
        "coff_colours.off": b"COFF\n4 4 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n"
                            b"0 0 1 1 1 1 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n4 1 2 3 3\n",
        "binary.off": off_binary(),
        "bare_header.off": b"OFF\n",
        "billions.off": b"OFF\n4000000000 4000000000 0\n0 0 0\n",
        "truncated_faces.off": off_ascii()[:-12],
        "float_limit.off": off_ascii([(0, 0, 0), (BIG, 0, 0), (0, BIG, 0), (0, 0, BIG)]),
        "nan_inf.off": off_ascii([(0, 0, 0), ("nan", 0, 0), (0, "inf", 0), (0, 0, "-inf")]),
        "index_out_of_range.off": off_ascii(faces=[(0, 1, 7)]),
    },
    "obj": {
        "tetra.obj": obj(),
        "corner_forms.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
                            b"f 1/1 2/1 3/1\nf 1//1 2//1 4//1\nf -4/1/1 -1/1/1 -2/1/1\nf 2 3 4\n",
        "off_saved_as.obj": off_ascii(),
        "huge_index.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967296\n",
        "nan.obj": obj([(0, 0, 0), ("nan", 0, 0), (0, 1, 0), (0, 0, 1)]),
        "float_limit.obj": obj([(0, 0, 0), (BIG, 0, 0), (0, BIG, 0), (0, 0, BIG)]),
    },
    "ply": {
        "tetra_ascii.ply": ply_ascii(),
        "tetra_le.ply": ply_binary(),
        "tetra_be.ply": ply_binary("binary_big_endian", ">"),
        "billions_le.ply": ply_binary(nv=4000000000, nf=4000000000),
        "billions_ascii.ply": ply_ascii(nv=4000000000),
        "huge_list.ply": ply_binary()[:-17] + struct.pack("<B", 255) + b"\0" * 16,
        "header_only.ply": b"ply\nformat ascii 1.0\nend_header\n",
    },
    "stl": {
        "tetra_ascii.stl": stl_ascii(),
        "tetra_binary.stl": stl_binary(),
        "binary_says_solid.stl": stl_binary(header=b"solid but binary"),
        "lying_count.stl": stl_binary(count=1000000000),
        "truncated.stl": stl_binary()[:-30],
        "float_limit.stl": stl_ascii().replace(b"vertex 1 0 0", b"vertex 3.4e38 0 0")
                                     .replace(b"vertex 0 1 0", b"vertex 0 3.4e38 0"),
    },
}


def write(harness, name, data):
    folder = os.path.join(HERE, "corpus", harness)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


# --- protobuf wire encoding, enough for the seeds (no protoc needed) ---------
def varint(n):
    out = b""
    n &= (1 << 64) - 1
    while True:
        b = n & 0x7F
        n >>= 7
        if n:
            out += bytes([b | 0x80])
        else:
            return out + bytes([b])


def field_varint(num, n):
    return varint(num << 3) + varint(n)


def field_bytes(num, data):
    return varint(num << 3 | 2) + varint(len(data)) + data


def field_double(num, x):
    return varint(num << 3 | 1) + struct.pack("<d", x)


def packed_floats(num, xs):
    return field_bytes(num, b"".join(struct.pack("<f", x) for x in xs))


def packed_varints(num, ns):
    return field_bytes(num, b"".join(varint(n) for n in ns))


def mesh_arrays(vertices, triangles):
    return packed_floats(1, [c for v in vertices for c in v]) + packed_varints(2, triangles)

# Two small JPEG files our EncodeJpeg wrote (common/render/jpeg.h, quality 75):
# a dark disc on white (24 x 24 grey) and a coloured box on white (20 x 16).
JPEG_GREY = bytes.fromhex(
    "ffd8ffe000104a46494600010100000100010000ffdb004300080606070605080707070909080a0c140d0c0b0b0c1912"
    "130f141d1a1f1e1d1a1c1c20242e2720222c231c1c2837292c30313434341f27393d38323c2e333432ffc0000b080018"
    "001801011100ffc4001f0000010501010101010100000000000000000102030405060708090a0bffc400b51000020103"
    "03020403050504040000017d01020300041105122131410613516107227114328191a1082342b1c11552d1f024336272"
    "82090a161718191a25262728292a3435363738393a434445464748494a535455565758595a636465666768696a737475"
    "767778797a838485868788898a92939495969798999aa2a3a4a5a6a7a8a9aab2b3b4b5b6b7b8b9bac2c3c4c5c6c7c8c9"
    "cad2d3d4d5d6d7d8d9dae1e2e3e4e5e6e7e8e9eaf1f2f3f4f5f6f7f8f9faffda0008010100003f00f7fae1ee3e2f7822"
    "dafcdab6b1bb6ef0d347048f18652063217e6ce49057230a79e99ed209e2b98239e0952586550f1c91b0657523208238"
    "208ef5c5fc5eb8bbb6f865aab5ab6ddde5c72b894a308da4507181f3672148240c31e7b1f95abe8df80971772f822f23"
    "99b75bc37ccb01329257288cca148c2ae4e783c966e0753ea13c115cc12413c492c32a9492391432ba9182083c10476a"
    "f2fb8f809e1896fccd1deea705bb6f2604910ed2482a158a92140dc30724e473c1cfa4e99a65968fa6c1a7e9f6e96f69"
    "02ec8e24e807f3249c924f24924f35ffd9")
JPEG_COLOUR = bytes.fromhex(
    "ffd8ffe000104a46494600010100000100010000ffdb004300080606070605080707070909080a0c140d0c0b0b0c1912"
    "130f141d1a1f1e1d1a1c1c20242e2720222c231c1c2837292c30313434341f27393d38323c2e333432ffdb0043010909"
    "090c0b0c180d0d1832211c21323232323232323232323232323232323232323232323232323232323232323232323232"
    "3232323232323232323232323232ffc00011080010001403012200021101031101ffc4001f0000010501010101010100"
    "000000000000000102030405060708090a0bffc400b5100002010303020403050504040000017d010203000411051221"
    "31410613516107227114328191a1082342b1c11552d1f02433627282090a161718191a25262728292a3435363738393a"
    "434445464748494a535455565758595a636465666768696a737475767778797a838485868788898a9293949596979899"
    "9aa2a3a4a5a6a7a8a9aab2b3b4b5b6b7b8b9bac2c3c4c5c6c7c8c9cad2d3d4d5d6d7d8d9dae1e2e3e4e5e6e7e8e9eaf1"
    "f2f3f4f5f6f7f8f9faffc4001f0100030101010101010101010000000000000102030405060708090a0bffc400b51100"
    "020102040403040705040400010277000102031104052131061241510761711322328108144291a1b1c109233352f015"
    "6272d10a162434e125f11718191a262728292a35363738393a434445464748494a535455565758595a63646566676869"
    "6a737475767778797a82838485868788898a92939495969798999aa2a3a4a5a6a7a8a9aab2b3b4b5b6b7b8b9bac2c3c4"
    "c5c6c7c8c9cad2d3d4d5d6d7d8d9dae2e3e4e5e6e7e8e9eaf2f3f4f5f6f7f8f9faffda000c03010002110311003f00f5"
    "0f19f89af7c3bf62fb2456efe7f99bbce5271b76e31823d4d72bff000b2f59ff009f6b0ffbf6ff00fc55755e33f0cdef"
    "88bec5f6496dd3c8f33779cc46776dc6300fa1ae57fe15a6b3ff003f361ff7f1ff00f89af2315f5bf6afd9dedff00f67"
    "09f53f62bdadb9bfe09ea9451457ae78c7ffd9")


def png(width, height, colour_type, rows):
    """A PNG file of 8-bit `rows` (bytes each, filter byte included)."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(b"".join(rows))) + chunk(b"IEND", b""))


def pictures():
    """Seeds of the picture harness: each kind the decoders read, and the
    hostile ones (truncated, 1 x 1, a header declaring 100,000 x 100,000)."""
    disc = [b"\0" + bytes(40 if (x - 8) ** 2 + (y - 8) ** 2 < 30 else 250 for x in range(16))
            for y in range(16)]
    alpha = [b"\0" + b"".join(bytes((200, 200, 200, 255 if 4 <= x < 12 and 2 <= y < 14 else 0))
                               for x in range(16)) for y in range(16)]
    write("picture", "grey.png", png(16, 16, 0, disc))
    write("picture", "alpha.png", png(16, 16, 6, alpha))
    write("picture", "one_pixel.png", png(1, 1, 2, [b"\0\x10\x20\x30"]))
    write("picture", "huge.png", png(100000, 100000, 0, [b"\0\0"]))
    write("picture", "truncated.png", png(16, 16, 0, disc)[:60])
    write("picture", "grey.jpg", JPEG_GREY)
    write("picture", "colour.jpg", JPEG_COLOUR)
    write("picture", "truncated.jpg", JPEG_COLOUR[:len(JPEG_COLOUR) * 2 // 3])
    write("picture", "not_a_picture.txt", b"GIF89a is not read")


def main():
    for fmt, seeds in MESH_SEEDS.items():
        for name, data in seeds.items():
            write("mesh_" + fmt, name, data)
    # Content detection: one valid file of each format and the ambiguous ones.
    for name in ["tetra.off", "comments_before_header.off", "binary.off", "bare_header.off"]:
        write("mesh_detect", name, MESH_SEEDS["off"][name])
    for name in ["tetra.obj", "corner_forms.obj"]:
        write("mesh_detect", name, MESH_SEEDS["obj"][name])
    for name in ["tetra_ascii.ply", "tetra_le.ply", "billions_le.ply"]:
        write("mesh_detect", name, MESH_SEEDS["ply"][name])
    for name in ["tetra_ascii.stl", "binary_says_solid.stl", "lying_count.stl"]:
        write("mesh_detect", name, MESH_SEEDS["stl"][name])

    manifests = {
        "valid.csv": b"id,class,path\nm1,chair,db/m1.off\nm2,chair,db/m2.off\nm3,-1,/abs/m3.ply\n",
        "quoted_bom_crlf.csv": b"\xef\xbb\xbfpath,extra,ID,Class\r\n\"a,b.off\", x ,\"q\"\"1\",c\r\n\r\n",
        "duplicate_id.csv": b"id,class,path\nm1,a,x.off\nm1,b,y.off\n",
        "unterminated.csv": b"id,class,path\n\"m1,a,x.off\n",
        "header_only.csv": b"id,class,path\n",
        "wrong_fields.csv": b"id,class,path\nm1,a\n",
    }
    for name, data in manifests.items():
        write("manifest", name, data)

    class_files = {
        "hierarchy.cla": b"PSB 1\n4 3\n\naircraft 0 0\n\nairplane aircraft 2\nm1\nm2\n\n"
                         b"glider aircraft 0\n\n-1 0 1\nm3\n",
        "crlf_tabs.cla": b"PSB 1\r\n1\t1\r\nchair 0 1\r\nm9",
        "billions.cla": b"PSB 1\n4000000000 4000000000\nc 0 4000000000\nm1\n",
        "truncated.cla": b"PSB 1\n2 3\na 0 2\nm1\n",
        "duplicate_model.cla": b"PSB 1\n2 2\na 0 1\nm1\nb 0 1\nm1\n",
        "undeclared_parent.cla": b"PSB 1\n1 0\na b 0\n",
    }
    for name, data in class_files.items():
        write("class_file", name, data)

    tri = [i for f in F for i in f]
    write("convert_mesh", "arrays.pb", field_bytes(1, mesh_arrays(V, tri)))
    write("convert_mesh", "file_off.pb",
          field_bytes(2, field_bytes(1, off_ascii()) + field_varint(2, 1) + field_bytes(3, b"t.off")))
    write("convert_mesh", "file_by_name.pb",
          field_bytes(2, field_bytes(1, stl_binary()) + field_bytes(3, b"t.stl")))
    write("convert_mesh", "nan.pb",
          field_bytes(1, mesh_arrays([(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)], [0, 1, 2])))
    write("convert_mesh", "float_limit.pb",
          field_bytes(1, mesh_arrays([(0, 0, 0), (BIG, 0, 0), (0, BIG, 0)], [0, 1, 2])))
    write("convert_mesh", "index_out_of_range.pb", field_bytes(1, mesh_arrays(V, [0, 1, 9])))
    write("convert_mesh", "not_multiple_of_3.pb", field_bytes(1, mesh_arrays(V, [0, 1])))

    def features(n, with_keypoints=True, dimension=128, descriptor_bytes=None):
        out = field_varint(1, n) + field_varint(2, dimension)
        out += field_bytes(3, bytes(range(128)) * n if descriptor_bytes is None else descriptor_bytes)
        if with_keypoints:
            out += packed_floats(4, [0.1] * 3 * n) + packed_floats(5, [0, 0, 1] * n)
            out += packed_floats(6, [0, 1, 0] * n) + packed_floats(7, [0.25] * n)
            out += packed_varints(8, [1] * n)
        return out
    write("convert_features", "two.pb", features(2))
    write("convert_features", "no_keypoints.pb", features(1, with_keypoints=False))
    write("convert_features", "billions.pb", features(4000000000, False, descriptor_bytes=b""))
    write("convert_features", "wrong_dimension.pb", features(1, dimension=64))
    write("convert_features", "nan_scale.pb",
          features(1, False) + packed_floats(4, [0, 0, 0]) + packed_floats(5, [0, 0, 1])
          + packed_floats(6, [0, 1, 0]) + packed_floats(7, [float("nan")]) + packed_varints(8, [0]))

    # Three points, each the neighbour of the others.
    graph = packed_floats(1, [0, 0, 0, 1, 0, 0, 0, 1, 0]) + packed_varints(2, [0, 2, 4, 6])
    write("convert_graph", "triangle.pb", graph + packed_varints(3, [1, 2, 0, 2, 0, 1]))
    write("convert_graph", "bad_offsets.pb", graph + packed_varints(3, [1]))
    # Once read past the neighbours (ValidatePointGraph checked offsets[n]
    # only): offsets[1] = 100 with one neighbour.
    write("convert_graph", "offsets_past_neighbours.pb",
          packed_floats(1, [0, 0, 0, 1, 0, 0]) + packed_varints(2, [0, 100, 1])
          + packed_varints(3, [1]))
    write("convert_graph", "inf.pb", packed_floats(1, [float("inf"), 0, 0])
          + packed_varints(2, [0, 0]))

    def histogram(size, bins, weights):
        return field_varint(1, size) + packed_varints(2, bins) + packed_floats(3, weights)
    write("convert_histogram", "valid.pb", histogram(10, [1, 3, 7], [0.25, 0.25, 0.5]))
    write("convert_histogram", "empty.pb", histogram(10, [], []))
    write("convert_histogram", "huge_size.pb", histogram(4000000000, [3999999999], [1.0]))
    write("convert_histogram", "nan.pb", histogram(10, [1, 2], [float("nan"), 1.0]))
    write("convert_histogram", "unsorted.pb", histogram(10, [3, 1], [0.5, 0.5]))
    write("convert_histogram", "mismatch.pb", histogram(10, [1, 2, 3], [1.0]))

    write("convert_params", "empty.pb", b"")
    write("convert_params", "rld.pb", field_varint(1, 3) + field_varint(7, 2000) + field_varint(8, 8)
          + field_bytes(13, b"up") + field_bytes(14, b"stretch") + field_varint(17, 500)
          + field_bytes(22, b"exact"))
    write("convert_params", "dld.pb", field_varint(1, 1) + field_double(2, 0.3)
          + field_varint(3, 256) + field_varint(6, 1) + field_varint(12, 32))
    write("convert_params", "negative.pb", field_varint(3, -5) + field_double(2, float("nan"))
          + field_varint(17, 2**31 - 1))
    write("convert_params", "bad_strings.pb", field_bytes(13, b"sideways")
          + field_bytes(22, b"magic"))
    pictures()
    return 0


if __name__ == "__main__":
    sys.exit(main())
