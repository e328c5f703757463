// MULT18X18D behavioural model for simulation (bumprtl sim/ecp5), written from Lattice's
// ECP5 sysDSP usage guide (TN1267): an 18 x 18 multiplier, A and B signed or unsigned per
// SIGNEDA / SIGNEDB, 36-bit product P. Each register group (INPUTA, INPUTB, PIPELINE,
// OUTPUT; INPUTC is unused by the product) is bypassed (REG_*_CLK = "NONE") or clocked by
// CLK0..3 with clock enable CE0..3 and reset RST0..3 (REG_*_CE, REG_*_RST), the reset
// synchronous or asynchronous per RESETMODE. SIGNEDA/SIGNEDB travel with their operand's
// input register. Modelled subset: SOURCEA/SOURCEB = 0 (no shift-register cascade),
// MULT_BYPASS = "DISABLED", CLKn_DIV ignored; anything else stops the simulation.
// SROA/SROB/ROA/ROB/ROC and SIGNEDP are driven (registered operands, sign of P).
module MULT18X18D(
  input A17, A16, A15, A14, A13, A12, A11, A10, A9, A8, A7, A6, A5, A4, A3, A2, A1, A0,
  input B17, B16, B15, B14, B13, B12, B11, B10, B9, B8, B7, B6, B5, B4, B3, B2, B1, B0,
  input C17, C16, C15, C14, C13, C12, C11, C10, C9, C8, C7, C6, C5, C4, C3, C2, C1, C0,
  input SIGNEDA, SIGNEDB, SOURCEA, SOURCEB,
  input CLK3, CLK2, CLK1, CLK0, CE3, CE2, CE1, CE0, RST3, RST2, RST1, RST0,
  input SRIA17, SRIA16, SRIA15, SRIA14, SRIA13, SRIA12, SRIA11, SRIA10, SRIA9, SRIA8, SRIA7, SRIA6, SRIA5, SRIA4, SRIA3, SRIA2, SRIA1, SRIA0,
  input SRIB17, SRIB16, SRIB15, SRIB14, SRIB13, SRIB12, SRIB11, SRIB10, SRIB9, SRIB8, SRIB7, SRIB6, SRIB5, SRIB4, SRIB3, SRIB2, SRIB1, SRIB0,
  output SROA17, SROA16, SROA15, SROA14, SROA13, SROA12, SROA11, SROA10, SROA9, SROA8, SROA7, SROA6, SROA5, SROA4, SROA3, SROA2, SROA1, SROA0,
  output SROB17, SROB16, SROB15, SROB14, SROB13, SROB12, SROB11, SROB10, SROB9, SROB8, SROB7, SROB6, SROB5, SROB4, SROB3, SROB2, SROB1, SROB0,
  output ROA17, ROA16, ROA15, ROA14, ROA13, ROA12, ROA11, ROA10, ROA9, ROA8, ROA7, ROA6, ROA5, ROA4, ROA3, ROA2, ROA1, ROA0,
  output ROB17, ROB16, ROB15, ROB14, ROB13, ROB12, ROB11, ROB10, ROB9, ROB8, ROB7, ROB6, ROB5, ROB4, ROB3, ROB2, ROB1, ROB0,
  output ROC17, ROC16, ROC15, ROC14, ROC13, ROC12, ROC11, ROC10, ROC9, ROC8, ROC7, ROC6, ROC5, ROC4, ROC3, ROC2, ROC1, ROC0,
  output P35, P34, P33, P32, P31, P30, P29, P28, P27, P26, P25, P24, P23, P22, P21, P20, P19, P18, P17, P16, P15, P14, P13, P12, P11, P10, P9, P8, P7, P6, P5, P4, P3, P2, P1, P0,
  output SIGNEDP
);
  parameter REG_INPUTA_CLK = "NONE";
  parameter REG_INPUTA_CE = "CE0";
  parameter REG_INPUTA_RST = "RST0";
  parameter REG_INPUTB_CLK = "NONE";
  parameter REG_INPUTB_CE = "CE0";
  parameter REG_INPUTB_RST = "RST0";
  parameter REG_INPUTC_CLK = "NONE";
  parameter REG_INPUTC_CE = "CE0";
  parameter REG_INPUTC_RST = "RST0";
  parameter REG_PIPELINE_CLK = "NONE";
  parameter REG_PIPELINE_CE = "CE0";
  parameter REG_PIPELINE_RST = "RST0";
  parameter REG_OUTPUT_CLK = "NONE";
  parameter REG_OUTPUT_CE = "CE0";
  parameter REG_OUTPUT_RST = "RST0";
  parameter CLK0_DIV = "ENABLED";
  parameter CLK1_DIV = "ENABLED";
  parameter CLK2_DIV = "ENABLED";
  parameter CLK3_DIV = "ENABLED";
  parameter HIGHSPEED_CLK = "NONE";
  parameter GSR = "ENABLED";
  parameter CAS_MATCH_REG = "FALSE";
  parameter SOURCEB_MODE = "B_SHIFT";
  parameter MULT_BYPASS = "DISABLED";
  parameter RESETMODE = "SYNC";

  wire [17:0] a = {A17, A16, A15, A14, A13, A12, A11, A10, A9, A8, A7, A6, A5, A4, A3, A2, A1, A0};
  wire [17:0] b = {B17, B16, B15, B14, B13, B12, B11, B10, B9, B8, B7, B6, B5, B4, B3, B2, B1, B0};
  wire [17:0] c = {C17, C16, C15, C14, C13, C12, C11, C10, C9, C8, C7, C6, C5, C4, C3, C2, C1, C0};
  wire [3:0] clk = {CLK3, CLK2, CLK1, CLK0};
  wire [3:0] ce = {CE3, CE2, CE1, CE0};
  wire [3:0] rst = {RST3, RST2, RST1, RST0};

  initial begin
    if (MULT_BYPASS != "DISABLED") begin
      $fatal(1, "MULT18X18D model: MULT_BYPASS = %s is not modelled", MULT_BYPASS);
    end
  end
  always @(SOURCEA or SOURCEB)
    if (SOURCEA === 1'b1 || SOURCEB === 1'b1) begin
      $fatal(1, "MULT18X18D model: SOURCEA/SOURCEB = 1 (cascade) is not modelled");
    end

  // Register group: {sign, value} through a flip-flop of clock/enable/reset n, or straight.
  wire [18:0] a_q, b_q, c_q;
  wire [36:0] m_q, p_q;
  wire [36:0] product;
  mult18x18d_reg #(.W(19), .CLK(REG_INPUTA_CLK), .CE(REG_INPUTA_CE), .RST(REG_INPUTA_RST), .RESETMODE(RESETMODE))
    ra (.clk(clk), .ce(ce), .rst(rst), .d({SIGNEDA, a}), .q(a_q));
  mult18x18d_reg #(.W(19), .CLK(REG_INPUTB_CLK), .CE(REG_INPUTB_CE), .RST(REG_INPUTB_RST), .RESETMODE(RESETMODE))
    rb (.clk(clk), .ce(ce), .rst(rst), .d({SIGNEDB, b}), .q(b_q));
  mult18x18d_reg #(.W(19), .CLK(REG_INPUTC_CLK), .CE(REG_INPUTC_CE), .RST(REG_INPUTC_RST), .RESETMODE(RESETMODE))
    rc (.clk(clk), .ce(ce), .rst(rst), .d({1'b0, c}), .q(c_q));
  // 19-bit signed operands: the sign bit is a[17] when signed, 0 when unsigned
  wire signed [18:0] sa = {a_q[18] & a_q[17], a_q[17:0]};
  wire signed [18:0] sb = {b_q[18] & b_q[17], b_q[17:0]};
  wire signed [37:0] full = sa * sb;
  assign product = {a_q[18] | b_q[18], full[35:0]};
  mult18x18d_reg #(.W(37), .CLK(REG_PIPELINE_CLK), .CE(REG_PIPELINE_CE), .RST(REG_PIPELINE_RST), .RESETMODE(RESETMODE))
    rm (.clk(clk), .ce(ce), .rst(rst), .d(product), .q(m_q));
  mult18x18d_reg #(.W(37), .CLK(REG_OUTPUT_CLK), .CE(REG_OUTPUT_CE), .RST(REG_OUTPUT_RST), .RESETMODE(RESETMODE))
    rp (.clk(clk), .ce(ce), .rst(rst), .d(m_q), .q(p_q));

  assign {P35, P34, P33, P32, P31, P30, P29, P28, P27, P26, P25, P24, P23, P22, P21, P20, P19, P18, P17, P16, P15, P14, P13, P12, P11, P10, P9, P8, P7, P6, P5, P4, P3, P2, P1, P0} = p_q[35:0];
  assign SIGNEDP = p_q[36] & p_q[35];
  assign {ROA17, ROA16, ROA15, ROA14, ROA13, ROA12, ROA11, ROA10, ROA9, ROA8, ROA7, ROA6, ROA5, ROA4, ROA3, ROA2, ROA1, ROA0} = a_q[17:0];
  assign {ROB17, ROB16, ROB15, ROB14, ROB13, ROB12, ROB11, ROB10, ROB9, ROB8, ROB7, ROB6, ROB5, ROB4, ROB3, ROB2, ROB1, ROB0} = b_q[17:0];
  assign {ROC17, ROC16, ROC15, ROC14, ROC13, ROC12, ROC11, ROC10, ROC9, ROC8, ROC7, ROC6, ROC5, ROC4, ROC3, ROC2, ROC1, ROC0} = c_q[17:0];
  assign {SROA17, SROA16, SROA15, SROA14, SROA13, SROA12, SROA11, SROA10, SROA9, SROA8, SROA7, SROA6, SROA5, SROA4, SROA3, SROA2, SROA1, SROA0} = a_q[17:0];
  assign {SROB17, SROB16, SROB15, SROB14, SROB13, SROB12, SROB11, SROB10, SROB9, SROB8, SROB7, SROB6, SROB5, SROB4, SROB3, SROB2, SROB1, SROB0} = b_q[17:0];
endmodule

// One register group of MULT18X18D: CLK = "NONE" passes d through; "CLKn" clocks it on
// clk[n] with enable ce[n] (CE = "CEn") and reset rst[n] (RST = "RSTn"; reset wins over
// the enable), synchronous or asynchronous per RESETMODE.
module mult18x18d_reg #(parameter W = 1, parameter CLK = "NONE", parameter CE = "CE0",
                        parameter RST = "RST0", parameter RESETMODE = "SYNC")
  (input [3:0] clk, input [3:0] ce, input [3:0] rst, input [W-1:0] d, output [W-1:0] q);
  localparam integer NC = CLK == "CLK0" ? 0 : CLK == "CLK1" ? 1 : CLK == "CLK2" ? 2 : CLK == "CLK3" ? 3 : -1;
  localparam integer NE = CE == "CE0" ? 0 : CE == "CE1" ? 1 : CE == "CE2" ? 2 : 3;
  localparam integer NR = RST == "RST0" ? 0 : RST == "RST1" ? 1 : RST == "RST2" ? 2 : 3;
  generate
    if (NC < 0) begin : bypass
      assign q = d;
    end else begin : flop
      reg [W-1:0] r = 0;
      assign q = r;
      if (RESETMODE == "ASYNC") begin : async
        always @(posedge clk[NC] or posedge rst[NR])
          if (rst[NR]) r <= 0; else if (ce[NE]) r <= d;
      end else begin : sync
        always @(posedge clk[NC])
          if (rst[NR]) r <= 0; else if (ce[NE]) r <= d;
      end
    end
  endgenerate
endmodule
