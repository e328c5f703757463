// DP16KD behavioural model for simulation (bumprtl sim/ecp5), written from Lattice's ECP5
// memory usage guide (TN1264). Yosys ships DP16KD only as a blackbox (share/ecp5/cells_sim.v
// declares its ports and parameters, no behaviour), so this model stands in for it.
//
// 18 Kbit true dual-port block RAM, ports A and B each DATA_WIDTH 18, 9, 4, 2 or 1
// (word address AD[13:4], AD[13:3], AD[13:2], AD[13:1], AD[13:0]; in x18 mode AD[1:0] are
// the byte enables of a write: AD0 bits 8:0, AD1 bits 17:9). The array is 1024 rows of 18
// bits: an x18 word is a row, an x9 word half a row (9-bit unit u = row 2u / 2u+1, low
// half first), an x4/x2/x1 word sits in the low 8 bits of 9-bit unit w / (8 / width) at bit
// width * (w % (8 / width)) (the 9th bit is parity, unused at those widths). INITVAL_rr
// holds rows 16 rr .. 16 rr + 15, row n of the 16 in bits 20 n + 17 : 20 n.
// A clock edge with CE and a matching chip select (CS[2:0] == CSDECODE) reads the word
// into the output latch, or writes it (WEx: NORMAL keeps the latch, WRITETHROUGH shows the
// new word, READBEFOREWRITE the old one). REGMODE OUTREG adds the output register, loaded
// from the latch when OCE; RST clears latch and register (RESETMODE SYNC: on the clock;
// ASYNC: at once). A read on one port in the cycle the other writes the same word returns
// the old word (the data sheet leaves such a collision undefined; the generic Memory
// returns the old word). DATA_WIDTH 36 (pseudo dual port) is not modelled.
module DP16KD(
  input DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9, DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0,
  input ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4, ADA3, ADA2, ADA1, ADA0,
  input CEA, OCEA, CLKA, WEA, RSTA,
  input CSA2, CSA1, CSA0,
  output DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9, DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0,
  input DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9, DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0,
  input ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4, ADB3, ADB2, ADB1, ADB0,
  input CEB, OCEB, CLKB, WEB, RSTB,
  input CSB2, CSB1, CSB0,
  output DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9, DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0
);
  parameter DATA_WIDTH_A = 18;
  parameter DATA_WIDTH_B = 18;
  parameter REGMODE_A = "NOREG";
  parameter REGMODE_B = "NOREG";
  parameter RESETMODE = "SYNC";
  parameter ASYNC_RESET_RELEASE = "SYNC";
  parameter CSDECODE_A = "0b000";
  parameter CSDECODE_B = "0b000";
  parameter WRITEMODE_A = "NORMAL";
  parameter WRITEMODE_B = "NORMAL";
  parameter GSR = "ENABLED";
  parameter INIT_DATA = "STATIC";
  parameter WID = 0;
  parameter INITVAL_00 = 320'h0;
  parameter INITVAL_01 = 320'h0;
  parameter INITVAL_02 = 320'h0;
  parameter INITVAL_03 = 320'h0;
  parameter INITVAL_04 = 320'h0;
  parameter INITVAL_05 = 320'h0;
  parameter INITVAL_06 = 320'h0;
  parameter INITVAL_07 = 320'h0;
  parameter INITVAL_08 = 320'h0;
  parameter INITVAL_09 = 320'h0;
  parameter INITVAL_0A = 320'h0;
  parameter INITVAL_0B = 320'h0;
  parameter INITVAL_0C = 320'h0;
  parameter INITVAL_0D = 320'h0;
  parameter INITVAL_0E = 320'h0;
  parameter INITVAL_0F = 320'h0;
  parameter INITVAL_10 = 320'h0;
  parameter INITVAL_11 = 320'h0;
  parameter INITVAL_12 = 320'h0;
  parameter INITVAL_13 = 320'h0;
  parameter INITVAL_14 = 320'h0;
  parameter INITVAL_15 = 320'h0;
  parameter INITVAL_16 = 320'h0;
  parameter INITVAL_17 = 320'h0;
  parameter INITVAL_18 = 320'h0;
  parameter INITVAL_19 = 320'h0;
  parameter INITVAL_1A = 320'h0;
  parameter INITVAL_1B = 320'h0;
  parameter INITVAL_1C = 320'h0;
  parameter INITVAL_1D = 320'h0;
  parameter INITVAL_1E = 320'h0;
  parameter INITVAL_1F = 320'h0;
  parameter INITVAL_20 = 320'h0;
  parameter INITVAL_21 = 320'h0;
  parameter INITVAL_22 = 320'h0;
  parameter INITVAL_23 = 320'h0;
  parameter INITVAL_24 = 320'h0;
  parameter INITVAL_25 = 320'h0;
  parameter INITVAL_26 = 320'h0;
  parameter INITVAL_27 = 320'h0;
  parameter INITVAL_28 = 320'h0;
  parameter INITVAL_29 = 320'h0;
  parameter INITVAL_2A = 320'h0;
  parameter INITVAL_2B = 320'h0;
  parameter INITVAL_2C = 320'h0;
  parameter INITVAL_2D = 320'h0;
  parameter INITVAL_2E = 320'h0;
  parameter INITVAL_2F = 320'h0;
  parameter INITVAL_30 = 320'h0;
  parameter INITVAL_31 = 320'h0;
  parameter INITVAL_32 = 320'h0;
  parameter INITVAL_33 = 320'h0;
  parameter INITVAL_34 = 320'h0;
  parameter INITVAL_35 = 320'h0;
  parameter INITVAL_36 = 320'h0;
  parameter INITVAL_37 = 320'h0;
  parameter INITVAL_38 = 320'h0;
  parameter INITVAL_39 = 320'h0;
  parameter INITVAL_3A = 320'h0;
  parameter INITVAL_3B = 320'h0;
  parameter INITVAL_3C = 320'h0;
  parameter INITVAL_3D = 320'h0;
  parameter INITVAL_3E = 320'h0;
  parameter INITVAL_3F = 320'h0;

  reg [17:0] rows [0:1023];

  task load_row(input integer r, input [319:0] v);
    integer n;
    for (n = 0; n < 16; n = n + 1) rows[r * 16 + n] = v[20 * n +: 18];
  endtask

  initial begin
    if (!((DATA_WIDTH_A == 18 || DATA_WIDTH_A == 9 || DATA_WIDTH_A == 4 || DATA_WIDTH_A == 2 || DATA_WIDTH_A == 1) &&
          (DATA_WIDTH_B == 18 || DATA_WIDTH_B == 9 || DATA_WIDTH_B == 4 || DATA_WIDTH_B == 2 || DATA_WIDTH_B == 1)))
      $fatal(1, "DP16KD model: DATA_WIDTH_A = %0d / DATA_WIDTH_B = %0d not modelled", DATA_WIDTH_A, DATA_WIDTH_B);
    load_row(0, INITVAL_00);
    load_row(1, INITVAL_01);
    load_row(2, INITVAL_02);
    load_row(3, INITVAL_03);
    load_row(4, INITVAL_04);
    load_row(5, INITVAL_05);
    load_row(6, INITVAL_06);
    load_row(7, INITVAL_07);
    load_row(8, INITVAL_08);
    load_row(9, INITVAL_09);
    load_row(10, INITVAL_0A);
    load_row(11, INITVAL_0B);
    load_row(12, INITVAL_0C);
    load_row(13, INITVAL_0D);
    load_row(14, INITVAL_0E);
    load_row(15, INITVAL_0F);
    load_row(16, INITVAL_10);
    load_row(17, INITVAL_11);
    load_row(18, INITVAL_12);
    load_row(19, INITVAL_13);
    load_row(20, INITVAL_14);
    load_row(21, INITVAL_15);
    load_row(22, INITVAL_16);
    load_row(23, INITVAL_17);
    load_row(24, INITVAL_18);
    load_row(25, INITVAL_19);
    load_row(26, INITVAL_1A);
    load_row(27, INITVAL_1B);
    load_row(28, INITVAL_1C);
    load_row(29, INITVAL_1D);
    load_row(30, INITVAL_1E);
    load_row(31, INITVAL_1F);
    load_row(32, INITVAL_20);
    load_row(33, INITVAL_21);
    load_row(34, INITVAL_22);
    load_row(35, INITVAL_23);
    load_row(36, INITVAL_24);
    load_row(37, INITVAL_25);
    load_row(38, INITVAL_26);
    load_row(39, INITVAL_27);
    load_row(40, INITVAL_28);
    load_row(41, INITVAL_29);
    load_row(42, INITVAL_2A);
    load_row(43, INITVAL_2B);
    load_row(44, INITVAL_2C);
    load_row(45, INITVAL_2D);
    load_row(46, INITVAL_2E);
    load_row(47, INITVAL_2F);
    load_row(48, INITVAL_30);
    load_row(49, INITVAL_31);
    load_row(50, INITVAL_32);
    load_row(51, INITVAL_33);
    load_row(52, INITVAL_34);
    load_row(53, INITVAL_35);
    load_row(54, INITVAL_36);
    load_row(55, INITVAL_37);
    load_row(56, INITVAL_38);
    load_row(57, INITVAL_39);
    load_row(58, INITVAL_3A);
    load_row(59, INITVAL_3B);
    load_row(60, INITVAL_3C);
    load_row(61, INITVAL_3D);
    load_row(62, INITVAL_3E);
    load_row(63, INITVAL_3F);
  end

  function [2:0] cs_bits(input [39:0] s);      // "0bXYZ" -> 3'bXYZ
    cs_bits = {s[23:16] == "1", s[15:8] == "1", s[7:0] == "1"};
  endfunction

  function [17:0] mask(input integer width);
    mask = (18'd1 << width) - 1;
  endfunction

  // Flat bit index (row * 18 + column) of bit j of word w at a width.
  function integer bit_at(input integer width, input integer w, input integer j);
    integer per, u;
    begin
      if (width == 18) bit_at = w * 18 + j;
      else if (width == 9) bit_at = w * 9 + j;
      else begin
        per = 8 / width;
        u = w / per;
        bit_at = u * 9 + width * (w % per) + j;
      end
    end
  endfunction

  function integer word_addr(input integer width, input [13:0] ad);
    word_addr = width == 18 ? ad[13:4] : width == 9 ? ad[13:3] : width == 4 ? ad[13:2] :
                width == 2 ? ad[13:1] : ad;
  endfunction

  function [17:0] read_word(input integer width, input [13:0] ad);
    integer j, k, w;
    reg [17:0] row;
    begin
      read_word = 0;
      w = word_addr(width, ad);
      for (j = 0; j < width; j = j + 1) begin
        k = bit_at(width, w, j);
        row = rows[k / 18];
        read_word[j] = row[k % 18];
      end
    end
  endfunction

  // Nonblocking per bit: a read at the same edge (either port) sees the old word.
  task write_word(input integer width, input [13:0] ad, input [17:0] d);
    integer j, k, w;
    begin
      w = word_addr(width, ad);
      for (j = 0; j < width; j = j + 1)
        if (width != 18 || (j < 9 ? ad[0] : ad[1])) begin
          k = bit_at(width, w, j);
          rows[k / 18][k % 18] <= d[j];
        end
    end
  endtask

  // ---- port A
  wire [13:0] ada = {ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4, ADA3, ADA2, ADA1, ADA0};
  wire [17:0] dia = {DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9, DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0};
  wire sela = {CSA2, CSA1, CSA0} == cs_bits(CSDECODE_A);
  reg [17:0] latch_a = 0, oreg_a = 0;
  wire [17:0] doa = REGMODE_A == "OUTREG" ? oreg_a : latch_a;
  assign {DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9, DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0} = doa;
  generate
    if (RESETMODE == "ASYNC") begin : rst_a_async
      always @(posedge RSTA) begin latch_a <= 0; oreg_a <= 0; end
    end
  endgenerate
  always @(posedge CLKA) begin
    if (RSTA) begin
      latch_a <= 0;
      oreg_a <= 0;
    end else begin
      if (OCEA) oreg_a <= latch_a;
      if (CEA && sela) begin
        if (WEA) begin
          write_word(DATA_WIDTH_A, ada, dia);
          if (WRITEMODE_A == "WRITETHROUGH") latch_a <= dia & mask(DATA_WIDTH_A);
          else if (WRITEMODE_A == "READBEFOREWRITE") latch_a <= read_word(DATA_WIDTH_A, ada);
        end else
          latch_a <= read_word(DATA_WIDTH_A, ada);
      end
    end
  end

  // ---- port B
  wire [13:0] adb = {ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4, ADB3, ADB2, ADB1, ADB0};
  wire [17:0] dib = {DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9, DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0};
  wire selb = {CSB2, CSB1, CSB0} == cs_bits(CSDECODE_B);
  reg [17:0] latch_b = 0, oreg_b = 0;
  wire [17:0] dob = REGMODE_B == "OUTREG" ? oreg_b : latch_b;
  assign {DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9, DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0} = dob;
  generate
    if (RESETMODE == "ASYNC") begin : rst_b_async
      always @(posedge RSTB) begin latch_b <= 0; oreg_b <= 0; end
    end
  endgenerate
  always @(posedge CLKB) begin
    if (RSTB) begin
      latch_b <= 0;
      oreg_b <= 0;
    end else begin
      if (OCEB) oreg_b <= latch_b;
      if (CEB && selb) begin
        if (WEB) begin
          write_word(DATA_WIDTH_B, adb, dib);
          if (WRITEMODE_B == "WRITETHROUGH") latch_b <= dib & mask(DATA_WIDTH_B);
          else if (WRITEMODE_B == "READBEFOREWRITE") latch_b <= read_word(DATA_WIDTH_B, adb);
        end else
          latch_b <= read_word(DATA_WIDTH_B, adb);
      end
    end
  end

endmodule
