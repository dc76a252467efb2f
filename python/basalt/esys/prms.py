"""esys.lsm's parameter classes that Basalt's front end maps onto its own models (docs/esys.md), and the
checkpoint and field-saver parameters. Each only holds its arguments; LsmMpi turns them into the scene."""

import math

from .vec3 import Vec3


class NRotElasticPrms:
    """Linear elastic repulsion between touching spheres. scaling=True (3-D): k = normalK (r1 + r2)/4."""

    def __init__(self, name, normalK, scaling=True):
        self.name, self.normalK, self.scaling = str(name), float(normalK), bool(scaling)


class NRotBondPrms:
    """Linear elastic bonds between the connections of `tag` (createConnections): rest length r1 + r2, break
    when (d - r0)/r0 > breakDistance; scaling=True (3-D): k = normalK (r1 + r2)/4."""

    def __init__(self, name, normalK, breakDistance, tag=0, scaling=True):
        self.name, self.normalK, self.breakDistance = str(name), float(normalK), float(breakDistance)
        self.tag, self.scaling = int(tag), bool(scaling)


class NRotElasticWallPrms:
    """A wall's elastic repulsion: k = pi r normalK in 3-D (ESyS's convention)."""

    def __init__(self, name, wallName, normalK):
        self.name, self.wallName, self.normalK = str(name), str(wallName), float(normalK)


class GravityPrms:
    def __init__(self, name, acceleration):
        self.name, self.acceleration = str(name), Vec3(acceleration)


class LinDampingPrms:
    """ESyS's linear viscous damping (its iterative rule, maxIterations as ESyS: docs/reference-runs.md)."""

    def __init__(self, name, viscosity, maxIterations=100):
        self.name, self.viscosity, self.maxIterations = str(name), float(viscosity), int(maxIterations)


class CheckPointPrms:
    def __init__(self, fileNamePrefix, beginTimeStep, endTimeStep, timeStepIncr):
        self.fileNamePrefix = str(fileNamePrefix)
        self.beginTimeStep, self.endTimeStep = int(beginTimeStep), int(endTimeStep)
        self.timeStepIncr = int(timeStepIncr)


class _SaverPrms:
    kind = ""

    def __init__(self, fieldName, fileName, fileFormat, beginTimeStep, endTimeStep, timeStepIncr):
        self.fieldName, self.fileName, self.fileFormat = str(fieldName), str(fileName), str(fileFormat)
        self.beginTimeStep, self.endTimeStep = int(beginTimeStep), int(endTimeStep)
        self.timeStepIncr = int(timeStepIncr)


class ParticleScalarFieldSaverPrms(_SaverPrms):
    kind = "ParticleScalarFieldSaverPrms"


class ParticleVectorFieldSaverPrms(_SaverPrms):
    kind = "ParticleVectorFieldSaverPrms"


class WallVectorFieldSaverPrms(_SaverPrms):
    kind = "WallVectorFieldSaverPrms"

    def __init__(self, wallName, fieldName, fileName, fileFormat, beginTimeStep, endTimeStep, timeStepIncr):
        super().__init__(fieldName, fileName, fileFormat, beginTimeStep, endTimeStep, timeStepIncr)
        self.wallName = [wallName] if isinstance(wallName, str) else [str(w) for w in wallName]


class Runnable:
    """Base class of the objects run before or after each time step (addPre/PostTimeStepRunnable): run()."""

    def __init__(self):
        pass

    def run(self):
        pass


class RotFrictionPrms:
    """ESyS's RotFriction between RotSpheres (Basalt's rot_friction, convention "esys": docs/reference-runs.md,
    "Granular conventions"). rigid is accepted and, as in ESyS 2.3.5, has no effect (its master never sends it to
    the workers)."""

    def __init__(self, name, normalK, dynamicMu, staticMu, shearK, scaling=True, rigid=False, meanR_scaling=True):
        self.name, self.normalK, self.shearK = str(name), float(normalK), float(shearK)
        self.dynamicMu, self.staticMu = float(dynamicMu), float(staticMu)
        self.scaling, self.rigid, self.meanR_scaling = bool(scaling), bool(rigid), bool(meanR_scaling)


class FrictionPrms(RotFrictionPrms):
    """ESyS's FrictionPrms: the same rotational model with normalK = pi E, shearK = pi E / (2 (1 + nu)) and
    scaling=True (ESyS's RotFricInteraction.cpp)."""

    def __init__(self, name, youngsModulus, poissonsRatio, dynamicMu, staticMu, rigid=False, meanR_scaling=True):
        E, nu = float(youngsModulus), float(poissonsRatio)
        super().__init__(name, math.pi * E, dynamicMu, staticMu, math.pi * E / (2.0 * (1.0 + nu)), True, rigid,
                         meanR_scaling)


class NRotFrictionPrms:
    """ESyS's NRotFriction (Basalt's friction, convention "esys"): one coefficient dynamicMu for sticking and
    sliding; scaling=True: K and Ks times (r1 + r2)/2."""

    def __init__(self, name, normalK, dynamicMu, shearK, scaling=True):
        self.name, self.normalK, self.dynamicMu = str(name), float(normalK), float(dynamicMu)
        self.shearK, self.scaling = float(shearK), bool(scaling)


class RotDampingPrms:
    """ESyS's rotational viscous damping of RotSpheres (its iterative rule on the moment, maxIterations as ESyS)."""

    def __init__(self, name, viscosity, maxIterations=100):
        self.name, self.viscosity, self.maxIterations = str(name), float(viscosity), int(maxIterations)
