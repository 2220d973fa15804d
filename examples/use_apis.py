"""Call the planning and control APIs directly, no agent: plan a path, track a reference, check both.

Run it with ``python examples/use_apis.py``. Each API returns a typed result (status, the solver's
message, cost, solve time, and the trajectory); ``to_solution()`` hands it to the task's checker.
"""

from __future__ import annotations

from audere import scenarios
from audere.controllers import mpc
from audere.planners import rrt
from audere.viz import plot


def main() -> None:
    # a path among obstacles with informed RRT* (OMPL), checked exactly against the task
    easy = scenarios.make("plan-easy", seed=3)
    path = rrt(
        easy.world(inflated=False),
        easy.x0,
        easy.goal_position,
        algorithm="informed_rrt_star",
        time_limit=0.3,
        goal_tolerance=easy.goal_tolerance,
        margin=easy.margin,
    )
    report = easy.check(path.to_solution())
    print(f"rrt: {path.status} in {path.solve_time:.2f} s, length {path.cost:.2f} m -> {report.summary()}")
    plot(easy, path.to_solution(), report).savefig("plan-easy-rrt.png", dpi=100)

    # the paper's Track-car: nonlinear MPC (CasADi/IPOPT) in closed loop along the reference
    car = scenarios.make("track-car", seed=3)
    tracked = mpc(
        car.model or "unicycle",
        car.x0,
        reference=car.reference,
        steps=car.horizon,
        horizon=10,
        dt=car.dt,
        u_min=car.u_min,
        u_max=car.u_max,
    )
    report = car.check(tracked.to_solution())
    print(f"mpc: {tracked.status} in {tracked.solve_time:.2f} s -> {report.summary()}")
    plot(car, tracked.to_solution(), report).savefig("track-car-mpc.png", dpi=100)
    print("wrote plan-easy-rrt.png and track-car-mpc.png")


if __name__ == "__main__":
    main()
