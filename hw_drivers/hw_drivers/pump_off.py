"""Force the pump line off once (for systemd ``ExecStopPost=``, after any kind of exit).

``pump_off --chip /dev/gpiochip0 --line GPIO17 [--active-low]``: requests the line as an
output with the inactive value and releases it. Exit status 0 on success, 1 otherwise.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from hw_drivers.errors import FatalDeviceError
from hw_drivers.pump_output import GpiodPumpOutput, parse_line_id

__all__ = ['main']


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of ``pump_off``."""
    parser = argparse.ArgumentParser(description='Drive the pump GPIO line inactive (pump off).')
    parser.add_argument('--chip', default='/dev/gpiochip0')
    parser.add_argument('--line', default='GPIO17')
    parser.add_argument('--active-low', action='store_true')
    args = parser.parse_args(argv)
    try:
        output = GpiodPumpOutput(
            args.chip, parse_line_id(args.line), active_low=args.active_low, consumer='pump-off'
        )
        output.close()
    except FatalDeviceError as err:
        sys.stderr.write(f'pump_off: {err}\n')
        sys.exit(1)


if __name__ == '__main__':
    main()
