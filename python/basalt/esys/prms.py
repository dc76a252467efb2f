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


class NRotBondedWallPrms:
    """ESyS's NRotBondedWall: the particles of particleTag near the wall are tied to it by F = -k (u_p - u_w), the
    particle's displacement since its creation against the wall's since its creation (the full vector), k = pi r
    normalK (3-D); the group's other particles near the wall get the elastic wall with the same normalK
    (ESyS's BWallInteraction, BWallInteractionGroup). tagMask: which bits of the tag count (-1: all)."""

    def __init__(self, name, wallName, normalK, particleTag, tagMask=-1):
        self.name, self.wallName, self.normalK = str(name), str(wallName), float(normalK)
        self.particleTag, self.tagMask = int(particleTag), int(tagMask)


class NRotElasticTriMeshPrms:
    """ESyS's elastic repulsion of a triangle mesh (readMesh): k = pi r normalK (3-D) times the overlap, along the
    line from the contact point (on a face, an edge or a corner) to the centre (ESyS's ETriangleInteraction,
    EEdgeInteraction, ECornerInteraction)."""

    def __init__(self, name, meshName, normalK):
        self.name, self.meshName, self.normalK = str(name), str(meshName), float(normalK)


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


class InteractionScalarFieldSaverPrms(_SaverPrms):
    kind = "InteractionScalarFieldSaverPrms"

    def __init__(self, interactionName, fieldName, fileName, fileFormat, beginTimeStep, endTimeStep, timeStepIncr):
        super().__init__(fieldName, fileName, fileFormat, beginTimeStep, endTimeStep, timeStepIncr)
        self.interactionName = str(interactionName)


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


class RotBondPrms:
    """ESyS's RotBond between RotSpheres (Basalt's rot_bond, rest length r1 + r2): normal, shear, torsion and
    bending springs and their strengths. scaling=True (ESyS's default): per bond, with R = L/2 (meanR_scaling) or
    min(r1, r2), kn, ks x R^2/L, kb x R^4/(4L), kt x R^4/(2L), strengths x R^2, R^2, R^3/4 (bending), R^3/2
    (torsion) (ESyS's CRotBondedInteraction). The criterion is ESyS's direct Mohr-Coulomb (truncated, beta1 =
    beta2 = 1)."""

    def __init__(self, name, normalK, shearK, torsionK, bendingK, normalBrkForce, shearBrkForce, torsionBrkForce,
                 bendingBrkForce, tag=0, scaling=True, meanR_scaling=True, truncated=1.0):
        self.name, self.tag = str(name), int(tag)
        self.kn, self.ks, self.kt, self.kb = float(normalK), float(shearK), float(torsionK), float(bendingK)
        self.fn_max, self.fs_max = float(normalBrkForce), float(shearBrkForce)
        self.mt_max, self.mb_max = float(torsionBrkForce), float(bendingBrkForce)
        self.scaling, self.meanR_scaling, self.truncated = bool(scaling), bool(meanR_scaling), float(truncated)
        self.beta1 = self.beta2 = 1.0

    def model(self):
        """The rot_bond interaction of this group (without its bond_tag)."""
        m = {"type": "rot_bond", "kn": self.kn, "ks": self.ks, "kb": self.kb, "kt": self.kt,
             "max_normal_force": self.fn_max, "max_shear_force": self.fs_max, "max_bending_moment": self.mb_max,
             "max_torsion_moment": self.mt_max, "scaling": self.scaling, "criterion": "esys",
             "truncated": self.truncated, "beta1": self.beta1, "beta2": self.beta2, "rest_length": "sum_of_radii"}
        if self.scaling:
            m["radius_scaling"] = "mean" if self.meanR_scaling else "min"
        return m


class BrittleBeamPrms:
    """ESyS's BrittleBeam (RotBond from elastic beam theory, always scaled per bond): kn = pi E R^2/L, ks = pi G
    R^2/L, kb = pi E R^4/(4L), kt = pi G R^4/(2L), strengths from cohesion and tanAngle; Basalt's rot_bond with
    youngs_modulus (docs/reference-runs.md, "Rotational bonds")."""

    def __init__(self, name, youngsModulus, poissonsRatio, cohesion, tanAngle, tag=0, meanR_scaling=True,
                 truncated=1.0, beta1=1.0, beta2=1.0):
        self.name, self.tag = str(name), int(tag)
        self.E, self.nu, self.cohesion, self.tanAngle = (float(youngsModulus), float(poissonsRatio),
                                                         float(cohesion), float(tanAngle))
        self.meanR_scaling, self.truncated = bool(meanR_scaling), float(truncated)
        self.beta1, self.beta2 = float(beta1), float(beta2)

    def model(self):
        return {"type": "rot_bond", "youngs_modulus": self.E, "poissons_ratio": self.nu,
                "radius_scaling": "mean" if self.meanR_scaling else "min", "cohesion": self.cohesion,
                "tan_friction_angle": self.tanAngle, "criterion": "esys", "truncated": self.truncated,
                "beta1": self.beta1, "beta2": self.beta2, "rest_length": "sum_of_radii"}
