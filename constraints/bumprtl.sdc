# Generic SDC for other flows (vendor tools, nextpnr --sdc): the same 150 MHz clock as
# constraints/ecp5.lpf on the single sync domain's clock port of every emitted unit.
create_clock -name clk -period 6.667 [get_ports clk]
