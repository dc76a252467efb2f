"""Reader for ESyS-Particle's LSMGeometry 1.2 text format (.geo), shared by the peer-code scripts."""


class GeoError(Exception):
    pass


def read_geo(path):
    """Reads an LSMGeometry 1.2 text file: returns (box_lo, box_hi, particles, bonds).

    particles: list of (id, x, y, z, r, tag); bonds: list of (id1, id2, tag)."""
    try:
        with open(path) as f:
            lines = f.read().split("\n")
    except OSError as e:
        raise GeoError(f"{path}: cannot read: {e.strerror}")
    pos = 0

    def next_line(what):
        nonlocal pos
        while pos < len(lines) and not lines[pos].strip():
            pos += 1
        if pos >= len(lines):
            raise GeoError(f"{path}: unexpected end of file, expected {what}")
        pos += 1
        return pos, lines[pos - 1].split()

    def numbers(lineno, words, count, what):
        if len(words) < count:
            raise GeoError(f"{path}:{lineno}: expected {count} numbers for {what}, got '{' '.join(words)}'")
        try:
            return [float(w) for w in words[:count]]
        except ValueError:
            raise GeoError(f"{path}:{lineno}: non-numeric {what}: '{' '.join(words)}'")

    lineno, words = next_line("LSMGeometry header")
    if words[:1] != ["LSMGeometry"]:
        raise GeoError(f"{path}:{lineno}: not an LSMGeometry file (first line '{' '.join(words)}')")
    box_lo = box_hi = None
    while True:
        lineno, words = next_line("BeginParticles")
        if words[0] == "BoundingBox":
            b = numbers(lineno, words[1:], 6, "BoundingBox")
            box_lo, box_hi = b[:3], b[3:]
        elif words[0] == "BeginParticles":
            break
    lineno, words = next_line("particle type")
    if words[0] != "Simple":
        raise GeoError(f"{path}:{lineno}: particle type '{words[0]}' unsupported (only Simple)")
    lineno, words = next_line("particle count")
    count = int(numbers(lineno, words, 1, "particle count")[0])
    particles = []
    for _ in range(count):
        lineno, words = next_line("a particle line")
        x, y, z, r, pid, tag = numbers(lineno, words, 6, "particle 'x y z r id tag'")
        if r <= 0:
            raise GeoError(f"{path}:{lineno}: radius must be positive, got {r}")
        particles.append((int(pid), x, y, z, r, int(tag)))
    lineno, words = next_line("EndParticles")
    if words[0] != "EndParticles":
        raise GeoError(f"{path}:{lineno}: expected EndParticles, got '{' '.join(words)}'")
    bonds = []
    if pos < len(lines):
        try:
            lineno, words = next_line("BeginConnect")
        except GeoError:
            words = []
        if words[:1] == ["BeginConnect"]:
            lineno, words = next_line("bond count")
            nb = int(numbers(lineno, words, 1, "bond count")[0])
            ids = {p[0] for p in particles}
            for _ in range(nb):
                lineno, words = next_line("a bond line")
                a, b, t = (int(v) for v in numbers(lineno, words, 3, "bond 'id1 id2 tag'"))
                if a not in ids or b not in ids:
                    raise GeoError(f"{path}:{lineno}: bond {a}-{b} names an unknown particle id")
                bonds.append((a, b, t))
    if box_lo is None:
        box_lo = [min(p[i + 1] - p[4] for p in particles) for i in range(3)]
        box_hi = [max(p[i + 1] + p[4] for p in particles) for i in range(3)]
    return box_lo, box_hi, particles, bonds
