"""OpenSees uniaxial materials of a model's springs: storeys and planes, contact points, links.

Each function gives the arguments of one ``uniaxialMaterial`` (after its tag) for one part of
the description; :mod:`pounding.export.opensees_elements` puts them on ``zeroLength``
elements.  Every material is the one a planar storey, a contact or a link gets, whatever the
floors' degrees of freedom (a plane of a building in plan is a storey's spring on the drift of
its line).

* storeys and planes (:func:`storey_material`): ``Elastic(k)``; ``Steel01(F_y, k, α, 0, 1, 0, 1)``
  for ``bilinear`` (kinematic hardening, isotropic hardening off); ``BoucWen(α, k, n, γ/u_yⁿ,
  β/u_yⁿ, A, 0, 0, 0, 1e-12·u_y, 100)`` for ``bouc-wen`` (OpenSees' z is in length units,
  z_o = u_y·z; in its code ``gamma`` is the constant term and ``beta`` multiplies
  sgn(Δε·z_o)); ``IMKBilin``, ``IMKPeakOriented`` or ``IMKPinching`` for the IMK models
  (:func:`imk_material`: drift ratios × h, OpenSees' Λ = Λ·h);
* contacts (:func:`contact_material`): ``Hertzdamp Kh xiNorm −gap`` for ``hertz-damp``
  (xiNorm = p(e) of the ξ formula) and ``hertz`` (xiNorm = 0), ``ElasticPPGap`` for ``linear``,
  ``ImpactMaterial K1 K2 −δy −gap`` for ``bilinear``; the other laws are refused in one line
  with the reason (:data:`CONTACT_LAWS_WITHOUT_MATERIAL`);
* links (:func:`link_materials`): ``Viscous(c, 1)``, ``Parallel`` of ``Elastic(k)`` and
  ``Viscous(c, 1)`` (Kelvin), ``ViscousDamper(k, c, 1)`` (Maxwell).
"""

from __future__ import annotations

from pounding.errors import PoundingError

__all__ = ["storey_material", "imk_material", "contact_material", "link_materials", "BILINEAR_NOTE",
           "HERTZDAMP_CLAMP_NOTE", "CONTACT_LAWS_WITHOUT_MATERIAL", "IMK_MATERIALS", "LAMBDA_OFF",
           "PART_TAG_OFFSET"]

#: What an exported ``law: bilinear`` contact does differently (OpenSees' ImpactMaterial::setTrialStrain).
BILINEAR_NOTE = ("bilinear (ImpactMaterial): in the step in which a gap closes, OpenSees starts the force from "
                 "K1 times the whole strain increment of that step, the part still open included (capped by the "
                 "loop's upper line); our solver starts it at the located closure")

#: What an exported ``hertz-damp`` contact with ``tension: clamp`` does differently.
HERTZDAMP_CLAMP_NOTE = ("hertz-damp with tension: clamp — OpenSees' Hertzdamp does not clamp the pull "
                        "before separation (it behaves as tension: allow)")

#: Contact laws OpenSees has no material for, and why (the refusal's reason).
CONTACT_LAWS_WITHOUT_MATERIAL = {
    "stereo-mechanical": "its impact is an instantaneous jump of the floors' velocities by the coefficient of "
                         "restitution, not a force on a deformation that a material can give",
    "kelvin": "it is a linear spring and a linear dashpot acting only while the gap is closed, and OpenSees' gap "
              "materials are elastic (ElasticPPGap), hysteretic (ImpactMaterial) or Hertz-damped (Hertzdamp)",
    "jankowski": "it damps the approach only (none in the restitution phase), and no OpenSees material switches "
                 "its damping with the sign of the velocity",
    "bumper": "its hard face engages inside the layer at the compression limit with its own impact velocity, "
              "which no single OpenSees gap material gives",
}

#: Material tags of the parts of a Parallel link material: this offset plus 2·element (+1).
PART_TAG_OFFSET = 1_000_000

#: OpenSees' Λ (m) written for a mode switched off (Λ = 0 here): OpenSees has no off switch, and with
#: E_t = 1e20·F_y its β = (E_i / (E_t − ΣE))^c is ~1e-20 (Λ = 0 there gives β ≤ 0, clipped to 0 for c = 1
#: but NaN for another c).
LAMBDA_OFF = 1.0e20

#: OpenSees material of each IMK variant (pounding.hysteresis.ImkStorey.variant).
IMK_MATERIALS = {"bilinear": "IMKBilin", "peak-oriented": "IMKPeakOriented", "pinching": "IMKPinching"}


def contact_material(law, gap: float) -> tuple[list, list[str]]:
    """OpenSees material arguments (after the tag) of one contact point, and notes on what it does differently.

    Parameters
    ----------
    law : ContactLaw
    gap : float
        Separation at rest, m.

    Raises
    ------
    PoundingError
        One line naming the law and why OpenSees has no material for it.
    """
    from pounding.contact.laws import Bilinear, Hertz, HertzDamp, Linear

    if isinstance(law, HertzDamp):
        notes = [HERTZDAMP_CLAMP_NOTE] if law.tension == "clamp" else []
        return ["Hertzdamp", float(law.kh), float(law.p), -float(gap)], notes
    if isinstance(law, Hertz):
        return ["Hertzdamp", float(law.kh), 0.0, -float(gap)], []
    if isinstance(law, Linear):
        # Compression-only elastic gap: ElasticPPGap E Fy gap with a yield force it never reaches.
        return ["ElasticPPGap", float(law.k), -1.0e30, -float(gap)], []
    if isinstance(law, Bilinear):
        # Muthukumar's element is OpenSees' ImpactMaterial K1 K2 δy gap, compression negative: our K2 > 0
        # check (kernel_parameters) first, so a loop that cannot be built is refused as in a run.
        k1, k2, dy = (float(x) for x in law.kernel_parameters(1.0, 1.0)[:3])
        return ["ImpactMaterial", k1, k2, -dy, -float(gap)], [BILINEAR_NOTE]
    reason = CONTACT_LAWS_WITHOUT_MATERIAL.get(law.name, "OpenSees has no material with its force law")
    raise PoundingError(f"contact law '{law.name}' has no OpenSees counterpart: {reason} (the export writes "
                        "hertz-damp, hertz, linear and bilinear contacts)")


def link_materials(law, element: int) -> list[list]:
    """OpenSees materials of one link: ``[tag, type, args...]`` rows, the last one the element's (tag *element*)."""
    from pounding.contact.links import KelvinLink, MaxwellLink, ViscousLink

    if isinstance(law, ViscousLink):
        return [[element, "Viscous", float(law.damping), 1.0]]
    if isinstance(law, KelvinLink):
        spring, dashpot = PART_TAG_OFFSET + 2 * element, PART_TAG_OFFSET + 2 * element + 1
        return [[spring, "Elastic", float(law.stiffness)], [dashpot, "Viscous", float(law.damping), 1.0],
                [element, "Parallel", spring, dashpot]]
    if isinstance(law, MaxwellLink):
        # ViscousDamper K Cd alpha: the Maxwell model of a fluid damper (Akcelyan, Lignos & Hikino 2018).
        return [[element, "ViscousDamper", float(law.stiffness), float(law.damping), 1.0]]
    raise PoundingError(f"link law '{law.name}' has no OpenSees counterpart in this exporter "
                        "(supported: viscous, kelvin, maxwell)")


def imk_material(law, stiffness: float, height: float) -> list:
    """``IMKBilin | IMKPeakOriented | IMKPinching`` arguments (after the tag) of an IMK storey.

    ``Ke, then per direction (positive, then negative, magnitudes) Up Upc Uu Fy FcapFy FresFy``
    (m, m, m, N, -, -), then ``Λ_s Λ_c [Λ_a] Λ_k c_s c_c [c_a] c_k D+ D−`` with OpenSees' Λ = E_t / F_y+
    = Λ·h (m; :data:`LAMBDA_OFF` for a mode switched off), then ``κ_f κ_d`` for IMKPinching
    (the argument order of OpenSees' ``OPS_IMKBilin`` / ``OPS_IMKPeakOriented`` / ``OPS_IMKPinching``).

    Parameters
    ----------
    law : ImkStorey
    stiffness : float
        Elastic stiffness, N/m.
    height : float
        Storey height, m.
    """
    k = float(stiffness)
    p = law.backbone(k, height)
    fy = p["positive"]["fy"]

    def lam(energy: float) -> float:
        return energy / fy if energy > 0.0 else LAMBDA_OFF

    sides = []
    for sign in ("positive", "negative"):
        d = p[sign]
        sides += [d["up"], d["upc"], d["uu"], d["fy"], d["fcap_ratio"], d["fres_ratio"]]
    rates = [p["positive"]["d"], p["negative"]["d"]]
    if law.variant == "bilinear":
        tail = [lam(p["e_s"]), lam(p["e_c"]), lam(p["e_k"]), p["c_s"], p["c_c"], p["c_k"]] + rates
    else:
        tail = [lam(p["e_s"]), lam(p["e_c"]), lam(p["e_a"]), lam(p["e_k"]), p["c_s"], p["c_c"], p["c_a"],
                p["c_k"]] + rates
        if law.variant == "pinching":
            tail += [p["kappa_f"], p["kappa_d"]]
    return [IMK_MATERIALS[law.variant], k] + [float(x) for x in sides + tail]


def storey_material(law, stiffness: float, height: float) -> list:
    """OpenSees material arguments (after the tag) of a storey or a plane: Elastic, Steel01, BoucWen or IMK.

    Parameters
    ----------
    law : StoreyHysteresis or None
        None: elastic.
    stiffness : float
        Elastic stiffness, N/m.
    height : float
        Storey height, m.
    """
    from pounding.hysteresis import BilinearStorey, BoucWenStorey, ImkStorey

    k = float(stiffness)
    if law is None:
        return ["Elastic", k]
    if isinstance(law, ImkStorey):
        return imk_material(law, k, height)
    fy = float(law.yield_force_for(k, height))
    alpha = float(law.post_yield_ratio)
    if isinstance(law, BilinearStorey):
        # Steel01 Fy E0 b a1 a2 a3 a4: a1 = a3 = 0 switch isotropic hardening off (kinematic only).
        return ["Steel01", fy, k, alpha, 0.0, 1.0, 0.0, 1.0]
    if isinstance(law, BoucWenStorey):
        # BoucWen alpha ko n gamma beta Ao deltaA deltaNu deltaEta tol maxIter.  OpenSees integrates
        # z_o = u_y z (m): dz_o/dε = Ao − |z_o|ⁿ (gamma + beta sgn(dε z_o)), so gamma = γ/u_yⁿ (the
        # constant term) and beta = β/u_yⁿ (the one multiplying the sign); no degradation.
        uy = fy / k
        scale = uy ** float(law.n)
        return ["BoucWen", alpha, k, float(law.n), float(law.gamma) / scale, float(law.beta) / scale,
                float(law.A), 0.0, 0.0, 0.0, 1.0e-12 * uy, 100]
    raise PoundingError(f"storey hysteresis '{law.name}' has no OpenSees counterpart in this exporter "
                        "(supported: bilinear, bouc-wen, imk-bilinear, imk-peak-oriented, imk-pinching)")
