#!/usr/bin/python3
"""Writes dji_constructed.jpg and dji_prefix.jpg: metadata-only JPEGs (a 64 x 48 grey image) whose
APP1 EXIF and XMP segments hold the values of public DJI metadata (PROVENANCE.md). Run from this
folder with a Python that has Pillow (/usr/bin/python3 on Debian); the output is committed."""
import io
import struct

from PIL import Image


def tiny_jpeg():
    out = io.BytesIO()
    Image.new("L", (64, 48), 128).save(out, "JPEG", quality=50)
    return out.getvalue()


def ifd(entries, base, next_data):
    """entries: (tag, type, count, bytes); values > 4 bytes go after the IFD at offset base."""
    entries = sorted(entries)
    head = struct.pack("<H", len(entries))
    data = b""
    data_at = base + 2 + 12 * len(entries) + 4
    for tag, typ, count, value in entries:
        if len(value) <= 4:
            head += struct.pack("<HHI", tag, typ, count) + value.ljust(4, b"\0")
        else:
            head += struct.pack("<HHII", tag, typ, count, data_at + len(data))
            data += value + (b"\0" if len(value) % 2 else b"")
    return head + struct.pack("<I", next_data) + data


def ascii(text):
    raw = text.encode() + b"\0"
    return (2, len(raw), raw)


def rationals(*pairs):
    return (5, len(pairs), b"".join(struct.pack("<II", a, b) for a, b in pairs))


def exif_segment():
    # GPS: 8 deg 17' 39.30" S, 115 deg 27' 42.59" E (DroneTM CSV row of DJI_20251002120847_0345_D.JPG)
    gps = {1: ascii("S"), 2: rationals((8, 1), (17, 1), (3930, 100)), 3: ascii("E"),
           4: rationals((115, 1), (27, 1), (4259, 100)), 5: (1, 1, b"\0"), 6: rationals((1131876, 1000))}
    exif = {0x9003: ascii("2025:10:02 12:08:47"), 0x920A: rationals((88, 10)),
            0xA405: (3, 1, struct.pack("<H", 24)), 0xA431: ascii("FIXTURE0001")}
    ifd0 = {0x010F: ascii("DJI"), 0x0110: ascii("FC6310R")}
    # layout: header 8, IFD0, Exif IFD, GPS IFD
    def build(offsets):
        e0 = [(t, *v) for t, v in ifd0.items()] + [(0x8769, 4, 1, struct.pack("<I", offsets[1])),
                                                   (0x8825, 4, 1, struct.pack("<I", offsets[2]))]
        b0 = ifd(e0, offsets[0], 0)
        b1 = ifd([(t, *v) for t, v in exif.items()], offsets[1], 0)
        b2 = ifd([(t, *v) for t, v in gps.items()], offsets[2], 0)
        return b0, b1, b2
    b0, b1, _ = build([8, 0, 0])
    offsets = [8, 8 + len(b0), 8 + len(b0) + len(b1)]
    b0, b1, b2 = build(offsets)
    tiff = b"II*\0" + struct.pack("<I", 8) + b0 + b1 + b2
    return b"Exif\0\0" + tiff


def xmp_segment(prefix):
    p = prefix
    body = f"""<?xpacket begin="\ufeff" id="W5M0MpCehiHzreSzNTczkc9d"?>
<x:xmpmeta xmlns:x="adobe:ns:meta/">
 <rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
  <rdf:Description rdf:about="" xmlns:tiff="http://ns.adobe.com/tiff/1.0/"
    xmlns:{p}="http://www.dji.com/drone-dji/1.0/"
    tiff:Make="DJI"
    {p}:AbsoluteAltitude="+1131.876"
    {p}:GpsLatitude="-8.2942500"
    {p}:GpsLongtitude="115.4618306"
    {p}:GimbalRollDegree="+0.00"
    {p}:GimbalYawDegree="-90.10"
    {p}:GimbalPitchDegree="-80.00"
    {p}:FlightRollDegree="+0.00"
    {p}:FlightYawDegree="-90.10"
    {p}:FlightPitchDegree="+0.00"
    {p}:RtkFlag="50"
    {p}:RtkStdLon="0.01234"
    {p}:RtkStdLat="0.01456"
    {p}:RtkStdHgt="0.02789"
    {p}:CalibratedFocalLength="3666.666504"
    {p}:CalibratedOpticalCenterX="2736.000000"
    {p}:CalibratedOpticalCenterY="1824.000000">
   <{p}:DewarpData>2018-09-06;3684.480000000000,3677.570000000000,2.240000000000,22.050000000000,-0.263482000000,0.106788000000,0.000037110700,-0.000327247000,-0.030078300000</{p}:DewarpData>
  </rdf:Description>
 </rdf:RDF>
</x:xmpmeta>
<?xpacket end="w"?>"""
    return b"http://ns.adobe.com/xap/1.0/\0" + body.encode()


def segment(marker, payload):
    return struct.pack(">BBH", 0xFF, marker, len(payload) + 2) + payload


def write(name, prefix):
    jpeg = tiny_jpeg()
    data = jpeg[:2] + segment(0xE1, exif_segment()) + segment(0xE1, xmp_segment(prefix)) + jpeg[2:]
    with open(name, "wb") as f:
        f.write(data)


write("dji_constructed.jpg", "drone-dji")
write("dji_prefix.jpg", "dji")
