"""A formulation with the displacement u and one extra named field phi, written in this file only
(no package file edited), traced by ``follow_path``: it declares its field (``FieldSpec``) and its
history (``history_spec``, two variables per integration point), and the solver numbers, allocates,
carries and checks them.

The toy: a bar 0 < x < L (cross-section A, u(0) = 0, pulled at x = L) whose stress is relaxed by a
field phi that solves a Helmholtz equation driven by the strain,

    sigma = E (eps - alpha phi),        phi - l^2 phi'' = eps + beta eps^2 + g0 cos(pi x / L),

with natural boundary conditions for phi. Equilibrium makes sigma uniform, so

* with g0 = 0 the state is uniform: eps = tau / L, phi = eps + beta eps^2 and the force is
  F = E A ((1 - alpha) eps - alpha beta eps^2), nonlinear in the control tau = u(L), and exactly
  representable (quadratic u, any phi space);
* with beta = 0, phi = sigma / (E (1 - alpha)) + g0 cos(pi x / L) / (1 - alpha + l^2 (pi / L)^2) and
  F = E A (1 - alpha) tau / L: the cosine part is approximated with the order of phi's space.
"""

import numpy as np
import pytest

from fracid.fem.mesh.assembly import assemble_vector, norm2
from fracid.fem.mesh.discretization import bar_discretization
from fracid.fem.mesh.dofs import Conditions, FieldSpec, number_dofs
from fracid.fem.formulations.forms import ElementArrays
from fracid.fem.path.path_following import ConvergenceError, StepOptions, follow_path
from fracid.fem.formulations.protocol import Problem
from fracid.fem.path.solver import NewtonOptions

L, A, E = 40.0, 2.0, 1000.0  # mm, mm^2, MPa


class CoupledBar:
    """The toy two-field problem of the module docstring on ``n_el`` equal bar elements.

    Parameters
    ----------
    space : str
        Scalar space of phi (``"linear"`` or ``"quadratic"``).
    alpha, beta, l2, g0 : float
        Coupling [-], nonlinearity of the source [-], l^2 [mm^2], amplitude of the fixed source [-].
    phi_tangent_factor : float
        Multiplies the phi-phi block of the tangent (1: consistent; else Newton converges linearly).
    """

    def __init__(self, n_el, space="linear", alpha=0.3, beta=0.0, l2=4.0, g0=0.0, phi_tangent_factor=1.0):
        self.disc = bar_discretization(np.linspace(0.0, L, n_el + 1), A)
        end = 2 * n_el
        conditions = Conditions(load={end: 1.0}, functionals={"end": {end: 1.0}}, fixed_dofs=(0,))
        self.dofs = number_dofs(self.disc, conditions, [FieldSpec("phi", space)])
        self.n_free, self.element_dofs, self.blocks = self.dofs.n_free, self.dofs.element_dofs, self.dofs.blocks
        self.load_vector, self.functionals = self.dofs.load_vector, self.dofs.functionals
        self.symmetry_factor = 1.0
        self.history_spec = {"phi_max": (), "eps_max": ()}  # largest phi and strain reached at each point
        self.space = self.disc.space(space)
        self.alpha, self.beta, self.factor = alpha, beta, phi_tangent_factor
        w, N, G = self.disc.weights, self.space.shape, self.space.gradient
        self.helmholtz = np.einsum("eq,qi,qj->eij", w, N, N) + l2 * np.einsum("eq,eqdi,eqdj->eij", w, G, G)
        self.g = g0 * np.cos(np.pi * self.disc.points[..., 0] / L)
        self.seen = []  # the largest history strain each evaluation is given

    def onset_ratio(self, history) -> float:
        return 0.0  # nothing softens

    def _state(self, q):
        qe = self.dofs.gather(q)
        B = self.disc.strain_operator[:, :, 0, :]
        eps = np.einsum("eqi,ei->eq", B, qe[:, self.dofs.columns["u"]])
        phi = qe[:, self.dofs.columns["phi"]] @ self.space.shape.T
        return qe, B, eps, phi, E * (eps - self.alpha * phi)

    def evaluate(self, q, history_old):
        assert set(history_old) == {"phi_max", "eps_max"} and history_old["eps_max"].shape == self.disc.weights.shape
        self.seen.append(float(history_old["eps_max"].max()))
        qe, B, eps, phi, sigma = self._state(q)
        w, N = self.disc.weights, self.space.shape
        f_u = np.einsum("eq,eqi->ei", w * sigma, B)
        source = (w * (eps + self.beta * eps**2 + self.g)) @ N
        f_phi = np.einsum("eij,ej->ei", self.helmholtz, qe[:, self.dofs.columns["phi"]]) - source
        tangent = np.block([[np.einsum("eq,eqi,eqj->eij", w * E, B, B),
                             -np.einsum("eq,eqi,qj->eij", w * E * self.alpha, B, N)],
                            [-np.einsum("eq,qi,eqj->eij", w * (1.0 + 2.0 * self.beta * eps), N, B),
                             self.factor * self.helmholtz]])
        history = {"phi_max": np.maximum(history_old["phi_max"], phi), "eps_max": np.maximum(history_old["eps_max"], eps)}
        arrays = ElementArrays(np.concatenate([f_u, f_phi], axis=1), tangent, {"u": f_u, "phi": source}, history,
                               outputs={"stress": sigma})
        residual = assemble_vector(self.element_dofs, arrays.residual, self.n_free)
        references = {name: norm2(assemble_vector(self.element_dofs[:, self.dofs.columns[name]], ref, self.n_free))
                      for name, ref in arrays.reference.items()}
        return residual, arrays, references

    def fields(self, q, history, arrays) -> dict:
        return {**self.dofs.split(q), **{k: v.copy() for k, v in history.items()}, "stress": arrays.outputs["stress"]}

    def elastic_energy(self, q, history, arrays) -> float:
        _, _, eps, _, sigma = self._state(q)
        return 0.5 * float(np.sum(self.disc.weights * sigma * eps))


def run(problem, target, n_steps=5, newton=NewtonOptions(rtol_u=1e-11, field_rtol={"phi": 1e-10})):
    steps = StepOptions(initial=target / n_steps, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    return follow_path(problem, "end", target, steps=steps, newton=newton, field_steps="all", linear_solver="superlu")


def relative_residuals(problem, result) -> dict:
    """Each field's residual at the last step relative to its reference (as the solver measures it)."""
    q = problem.dofs.restrict(np.concatenate([result.fields[result.n_steps][f] for f in ("u", "phi")]))
    residual, _, references = problem.evaluate(q, problem_history(problem))
    residual = residual - result.force[-1] * problem.load_vector
    return {name: norm2(residual[idx]) / max(references[name], abs(result.force[-1]) if name == "u" else 0.0)
            for name, idx in problem.blocks.items()}


def problem_history(problem):
    return {name: np.zeros(problem.disc.weights.shape) for name in problem.history_spec}


@pytest.mark.parametrize("space", ["linear", "quadratic"])
def test_nonlinear_uniform_state_is_traced_exactly(space):
    alpha, beta = 0.3, 50.0
    problem = CoupledBar(6, space, alpha=alpha, beta=beta)
    assert isinstance(problem, Problem) and list(problem.blocks) == ["u", "phi"]
    result = run(problem, target=0.16)  # eps up to 0.004, beta eps = 0.2
    assert result.n_steps == 5 and result.status == "target reached"
    eps = result.control / L
    np.testing.assert_allclose(result.force, E * A * ((1 - alpha) * eps - alpha * beta * eps**2), rtol=1e-9, atol=1e-12)
    last = result.fields[result.n_steps]
    np.testing.assert_allclose(last["phi"], eps[-1] + beta * eps[-1] ** 2, rtol=1e-9)
    np.testing.assert_allclose(last["stress"], result.force[-1] / A, rtol=1e-9)
    # the declared history was allocated (zeros), carried from step to step and returned
    np.testing.assert_allclose(last["eps_max"], eps[-1], rtol=1e-9)
    np.testing.assert_allclose(last["phi_max"], last["phi"][0], rtol=1e-9)
    seen = np.unique(np.round(np.array(problem.seen) * L, 9))
    np.testing.assert_allclose(seen, result.control[:-1], atol=1e-9)  # each step started from the last one's
    assert result.stats.iterations > result.n_steps  # the nonlinearity took Newton iterations
    energy = 0.5 * result.force * eps * L
    np.testing.assert_allclose(result.observables["elastic_energy"], energy, rtol=1e-9, atol=1e-15)
    errors = relative_residuals(problem, result)
    assert set(errors) == {"u", "phi"} and errors["u"] <= 1e-11 and errors["phi"] <= 1e-10


def phi_error(n_el, space):
    alpha, l2, g0 = 0.3, 4.0, 1e-3
    problem = CoupledBar(n_el, space, alpha=alpha, l2=l2, g0=g0)
    result = run(problem, target=0.1, n_steps=2)
    force = result.force[-1]
    assert force == pytest.approx(E * A * (1 - alpha) * 0.1 / L, rel=1e-9)
    x = np.linspace(0.0, L, problem.space.n_nodes)  # uniform mesh: the space's nodes
    k = np.pi / L
    exact = force / (A * E * (1 - alpha)) + g0 * np.cos(k * x) / (1 - alpha + l2 * k * k)
    return np.max(np.abs(result.fields[result.n_steps]["phi"] - exact)) / g0


@pytest.mark.parametrize("space, order", [("linear", 2), ("quadratic", 3)])
def test_helmholtz_field_converges_with_the_order_of_its_space(space, order):
    coarse, fine = phi_error(8, space), phi_error(16, space)
    assert coarse < 0.02
    assert np.log2(coarse / fine) > order - 0.3, (coarse, fine)


def test_the_solver_checks_the_named_field_against_its_own_tolerance():
    """A wrong phi-phi tangent makes Newton converge only linearly: with phi's tolerance tight and few
    iterations the step fails naming phi; with phi's tolerance loose the same run converges."""
    target, few = 0.16, dict(rtol_u=0.5, max_iterations=2, reuse_ratio=0.0)
    with pytest.raises(ConvergenceError, match=r"phi: \d"):
        run(CoupledBar(6, beta=50.0, phi_tangent_factor=1.5), target,
            newton=NewtonOptions(field_rtol={"phi": 1e-10}, **few))
    loose = run(CoupledBar(6, beta=50.0, phi_tangent_factor=1.5), target, newton=NewtonOptions(field_rtol={"phi": 0.5}, **few))
    assert loose.status == "target reached"
