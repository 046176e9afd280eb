"""pyserial URL handlers for tests: `refusing://PATH` opens the device PATH through a driver that refuses even
parity, as some USB serial adapters refuse settings they cannot do (pyserial then raises termios.error)."""
