"""NRotSphere and RotSphere (esys.lsm): the particles a script creates and the ones getParticleList returns."""

from .vec3 import Vec3


class NRotSphere:
    """NRotSphere(id, posn, radius, mass): a sphere that does not rotate. The tag is -1 until setTag (as ESyS).
    The mass is used as given (ESyS does not derive it from a density for particles made here)."""

    _kind = "NRotSphere"

    def __init__(self, id, posn, radius, mass):
        self._id, self._posn, self._radius, self._mass = int(id), Vec3(posn), float(radius), float(mass)
        self._tag = -1
        self._vel = Vec3(0.0, 0.0, 0.0)
        self._init = Vec3(posn)
        self._force = Vec3(0.0, 0.0, 0.0)

    def getId(self):
        return self._id

    def getID(self):
        return self._id

    def getTag(self):
        return self._tag

    def setTag(self, tag):
        self._tag = int(tag)

    def getPosn(self):
        return Vec3(self._posn)

    getPosition = getCentre = getCenter = getPosn

    def setPosn(self, posn):
        self._posn = Vec3(posn)
        self._init = Vec3(posn)

    setPosition = setPosn

    def getInitialPosn(self):
        return Vec3(self._init)

    getInitialPosition = getInitialPosn

    def getVelocity(self):
        return Vec3(self._vel)

    getLinearVelocity = getVelocity

    def setVelocity(self, v):
        self._vel = Vec3(v)

    setLinearVelocity = setVelocity

    def getRadius(self):
        return self._radius

    getRad = getRadius

    def getMass(self):
        return self._mass

    def getForce(self):
        return Vec3(self._force)

    getLinearForce = getForce

    def getMomentum(self):
        return self._vel * self._mass

    def __repr__(self):
        return f"{self._kind}(id={self._id}, posn={self._posn!r}, radius={self._radius}, mass={self._mass})"


class RotSphere(NRotSphere):
    """RotSphere(id, posn, radius, mass): a rotating sphere (moment of inertia 2/5 m r^2, as ESyS in 3-D)."""

    _kind = "RotSphere"

    def __init__(self, id, posn, radius, mass):
        super().__init__(id, posn, radius, mass)
        self._angvel = Vec3(0.0, 0.0, 0.0)

    def getAngularVelocity(self):
        return Vec3(self._angvel)

    def setAngularVelocity(self, w):
        self._angvel = Vec3(w)

    def getInertia(self):
        return 0.4 * self._mass * self._radius ** 2
