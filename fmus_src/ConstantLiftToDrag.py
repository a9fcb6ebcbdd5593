"""ConstantLiftToDrag FMU: a lift command at a fixed ratio to the measured drag (full lift up or down)."""

from aotv_cosim.fmu.slave import AotvSlave


class ConstantLiftToDrag(AotvSlave):
    """u = lift_to_drag * D/m: the vehicle flown at a constant lift-to-drag ratio, positive for
    full lift up, negative for full lift down (bank 0 or 180 deg of a lifting vehicle). The entry
    corridor's bounds are the passes flown so (`aotv_cosim.campaigns.corridor`)."""

    description = "Lift command at a constant ratio to the measured drag (corridor bounds)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("lift_to_drag", 0.3, "1", "Lift-to-drag ratio L/D flown (negative: lift down)")
        self.input("drag_acc", 0.0, "m/s2", "Measured drag specific force D/m", min=0.0)
        self.output("u", "m/s2", "Lift acceleration command L/m", lambda: self.lift_to_drag * self.drag_acc,
                    depends_on=("drag_acc",))

    def do_step(self, current_time, step_size):
        return True
