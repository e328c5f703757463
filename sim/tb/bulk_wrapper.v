// Simulation-only bulk wrapper around one emitted unit (sim/tb/bulk_wrapper.py fills it in
// from the unit's JSON sidecar; sim/tb/bulk.py builds and runs it). Not synthesisable; not
// part of any emitted unit.
//
// Stimulus words come from bulk_in.bin ($fread into a memory), traffic from two xorshift32
// generators, every output word goes to bulk_out.bin ($fwrite %u). With reset_prefix > 0 a
// run first offers that many cycles of junk pixels, every bit 1, to a stalled sink and then
// resets the unit for one cycle with them in flight: none may come out (with count = 0 that
// prefix is the whole run). With fill_hold > 0 each chunk first holds o.ready low until
// i.ready has been low (every credit spent) or the chunk's input all taken for fill_hold
// cycles: the unit's FIFO full, then drained under the random stalls. With BUMPRTL_BULK_DPI
// defined (Verilator) the same files go through DPI-C (bulk_dpi.cpp). With BULK_OWN_CLOCK
// defined (Icarus) the wrapper toggles clk itself; otherwise clk is an input, toggled by
// the Verilator build's C++ main (bulk_main.cpp).
//
// With BULK_AXI defined (a unit with an AXI4 read port, map_memory = "axi") the wrapper
// also holds the memory that port reads: bulk_axi.bin (the unit's _map.bin) loaded at
// time 0 from byte AXI_BASE on, ARREADY high while fewer than AXI_DEPTH bursts wait, each
// burst's beats in order, one a clock, from axi_latency cycles after its AR handshake; it
// counts the AR handshakes (ar_count) and sums their addresses (ar_sum).
//
// Parameters: IW, OW the unit's input and output payload widths, DEPTH the words of one
// chunk, HW the width of the host set-up word (0: the unit has no host ports), XW the
// width of the unit's other outputs, left unread, PERIOD the own clock's period; with
// BULK_AXI, AXI_DW and AXI_AW the port's data and address widths, AXI_BYTES the memory's
// bytes (a power of two), AXI_BASE the image's first byte address, AXI_DEPTH the bursts
// it holds. Macros: BULK_UNIT the unit's module name. The one text hook,
// the host-port connections of the unit instance, is a comment below that
// bulk_wrapper.py replaces (`.port(host_q[hi:lo])` per host port, `.port(unread[hi:lo])`
// per other output); as it stands the file is a complete module (linted on its own by
// tests/sim/tb/test_bulk_wrapper.py).
`ifndef BULK_UNIT
`define BULK_UNIT bulk_unit
`endif
module bulk_wrapper #(
  parameter IW = 8,
  parameter OW = 8,
  parameter DEPTH = 16,
  parameter HW = 0,
  parameter XW = 0,
  /* verilator lint_off UNUSEDPARAM */  // used with BULK_OWN_CLOCK only, BULK_AXI only
  parameter PERIOD = 10,
  parameter AXI_DW = 32,
  parameter AXI_AW = 32,
  parameter AXI_BYTES = 16,
  parameter AXI_BASE = 0,
  parameter AXI_DEPTH = 64,
  /* verilator lint_on UNUSEDPARAM */
  localparam AW = (DEPTH > 1 ? $clog2(DEPTH) : 1) + 1,  // counts 0..DEPTH inclusive
  localparam DENSITY_BITS = 16         // a gap / stall when 16 LFSR bits < density
) (
`ifdef BULK_OWN_CLOCK
  output reg clk /*verilator public_flat_rw*/,
`else
  input wire clk /*verilator public_flat_rw*/,
`endif
`ifdef BULK_AXI
  input wire [15:0] axi_latency /*verilator public_flat_rw*/,
  output reg [31:0] ar_count /*verilator public_flat_rw*/,
  output reg [63:0] ar_sum /*verilator public_flat_rw*/,
`endif
  input wire rst /*verilator public_flat_rw*/,
  input wire start /*verilator public_flat_rw*/,
  input wire [AW-1:0] count /*verilator public_flat_rw*/,
  input wire [31:0] gap_seed /*verilator public_flat_rw*/,
  input wire [DENSITY_BITS:0] gap_density /*verilator public_flat_rw*/,
  input wire [31:0] bp_seed /*verilator public_flat_rw*/,
  input wire [DENSITY_BITS:0] bp_density /*verilator public_flat_rw*/,
  input wire [31:0] idle_limit /*verilator public_flat_rw*/,
  input wire [31:0] fill_hold /*verilator public_flat_rw*/,
  input wire [31:0] reset_prefix /*verilator public_flat_rw*/,
  input wire setup_mode /*verilator public_flat_rw*/,
  output reg done /*verilator public_flat_rw*/,
  output reg timed_out /*verilator public_flat_rw*/,
  output reg [AW-1:0] n_in /*verilator public_flat_rw*/,
  output reg [AW-1:0] n_out /*verilator public_flat_rw*/,
  output reg [47:0] cycles /*verilator public_flat_rw*/
);
  localparam HOST = HW > 0;
  localparam HWS = HOST ? HW : 1;      // widths and depths of the unused set-up memory
  localparam HDEPTH = HOST ? DEPTH : 1;
  localparam XWS = XW > 0 ? XW : 1;

`ifdef BUMPRTL_BULK_DPI
  import "DPI-C" function int bulk_dpi_open(input string in_path, input int count,
                                             input int iw, input string out_path, input int ow);
  import "DPI-C" function void bulk_dpi_get(input int index, output bit [IW-1:0] word);
  import "DPI-C" function void bulk_dpi_put(input bit [OW-1:0] word);
  import "DPI-C" function void bulk_dpi_close();
  reg [IW-1:0] word;
`else
  reg [IW-1:0] stim [0:DEPTH-1];
`endif
  // rst and the host ports reach the unit through registers: a top-level input that fed
  // the unit directly would put its whole next-state logic into Verilator's input-combo
  // region, evaluated at every time step. The host ports take the set-up word being
  // played (bulk_setup.bin), one word per clock.
  reg unit_rst;
  reg [HWS-1:0] host_q;
  reg [HWS-1:0] hmem [0:HDEPTH-1];
  reg [HWS-1:0] hword;
  reg playing;
  reg run;
  reg in_valid;
  reg [IW-1:0] in_payload;
  reg out_ready;
  reg [AW-1:0] rd;
  reg [31:0] gap_rng;
  reg [31:0] bp_rng;
  reg [31:0] idle;
  reg filling;                         // the chunk's first stall, until the FIFO is full
  reg junking;                         // the chunk's reset prefix: junk pixels, then a reset
  reg junk_rst;                        // the unit's reset at the prefix's end (one cycle)
  reg [31:0] junk_n;                   // junk pixel cycles so far
  wire dut_rst = unit_rst | junk_rst;
  reg [31:0] fill_n;                   // cycles i.ready low (or the input all taken) so far
  integer fd;
  integer nread;
  wire in_ready;
  wire out_valid;
  wire [OW-1:0] out_payload;
  wire [XWS-1:0] unread;               // the unit's other outputs (the palette's bank)
  wire take = in_valid & in_ready;
  wire give = out_valid & out_ready;

  function [31:0] xorshift32(input [31:0] x);
    reg [31:0] y;
    begin
      y = x ^ (x << 13);
      y = y ^ (y >> 17);
      xorshift32 = y ^ (y << 5);
    end
  endfunction
  wire [31:0] gap_next = xorshift32(gap_rng);
  wire [31:0] bp_next = xorshift32(bp_rng);
  wire gap = {1'b0, gap_next[31:32 - DENSITY_BITS]} < gap_density;
  wire stall = {1'b0, bp_next[31:32 - DENSITY_BITS]} < bp_density;

`ifdef BULK_AXI
  // The memory behind the unit's AXI4 read port (one ID: bursts answered in order).
  localparam AXB = AXI_DW / 8;                    // bytes a beat
  localparam QW = $clog2(AXI_DEPTH);
  localparam MW = $clog2(AXI_BYTES);
  reg [7:0] axmem [0:AXI_BYTES-1];
  reg [AXI_AW-1:0] ar_addr_q [0:AXI_DEPTH-1];
  reg [7:0] ar_len_q [0:AXI_DEPTH-1];
  reg [47:0] ar_due_q [0:AXI_DEPTH-1];
  reg [QW:0] ax_wr, ax_rd;                        // burst queue pointers, one bit wider
  reg [7:0] ax_beat;
  reg [47:0] ax_clock;
  /* verilator lint_off UNUSEDSIGNAL */           // ARID, ARSIZE, ARBURST: one ID, INCR
  wire ax_arid;
  wire [2:0] ax_arsize;
  wire [1:0] ax_arburst;
  /* verilator lint_on UNUSEDSIGNAL */
  wire ax_arvalid, ax_rready;
  wire [AXI_AW-1:0] ax_araddr;
  wire [7:0] ax_arlen;
  wire [QW-1:0] ax_head = ax_rd[QW-1:0];
  wire ax_empty = ax_wr == ax_rd;
  wire ax_arready = (ax_wr ^ ax_rd) != {1'b1, {QW{1'b0}}};   // not full
  wire ax_rvalid = !ax_empty && ax_clock >= ar_due_q[ax_head];
  wire ax_rlast = ax_beat == ar_len_q[ax_head];
  wire ax_rid = 1'b0;
  wire [1:0] ax_rresp = 2'b00;
  /* verilator lint_off UNUSEDSIGNAL */           // the image is AXI_BYTES, the address wider
  wire [AXI_AW-1:0] ax_at = ar_addr_q[ax_head] - AXI_BASE
                            + {{(AXI_AW - 8){1'b0}}, ax_beat} * AXB;
  /* verilator lint_on UNUSEDSIGNAL */
  wire [AXI_DW-1:0] ax_rdata;
  genvar ab;
  generate
    for (ab = 0; ab < AXB; ab = ab + 1) begin : axi_byte
      assign ax_rdata[8 * ab +: 8] = axmem[ax_at[MW-1:0] + ab];
    end
  endgenerate
  integer axfd;
  integer axread;
  initial begin
    axfd = $fopen("bulk_axi.bin", "rb");
    axread = $fread(axmem, axfd);
    $fclose(axfd);
  end
  always @(posedge clk) begin
    if (unit_rst) begin
      ax_wr <= {(QW + 1){1'b0}};
      ax_rd <= {(QW + 1){1'b0}};
      ax_beat <= 8'd0;
      ax_clock <= 48'd0;
      ar_count <= 32'd0;
      ar_sum <= 64'd0;
    end else if (junk_rst) begin         // the reset prefix: outstanding bursts dropped
      ax_wr <= {(QW + 1){1'b0}};
      ax_rd <= {(QW + 1){1'b0}};
      ax_beat <= 8'd0;
    end else begin
      ax_clock <= ax_clock + 48'd1;
      if (ax_arvalid && ax_arready) begin
        ar_addr_q[ax_wr[QW-1:0]] <= ax_araddr;
        ar_len_q[ax_wr[QW-1:0]] <= ax_arlen;
        ar_due_q[ax_wr[QW-1:0]] <= ax_clock + {32'd0, axi_latency};
        ax_wr <= ax_wr + 1'b1;
        ar_count <= ar_count + 32'd1;
        ar_sum <= ar_sum + {{(64 - AXI_AW){1'b0}}, ax_araddr};
      end
      if (ax_rvalid && ax_rready) begin
        if (ax_rlast) begin
          ax_beat <= 8'd0;
          ax_rd <= ax_rd + 1'b1;
        end else
          ax_beat <= ax_beat + 8'd1;
      end
    end
  end
`endif

  `BULK_UNIT dut (
    .clk(clk),
    .rst(dut_rst),
    .i__valid(in_valid),
    .i__payload(in_payload),
    .i__ready(in_ready),
    .o__valid(out_valid),
    .o__payload(out_payload),
    .o__ready(out_ready)/*@host_ports@*/
  );

`ifdef BULK_OWN_CLOCK
  // One time slot per cycle (the rising edge every PERIOD, the falling edge in the same
  // slot by a non-blocking assignment: nothing in the unit or the wrapper waits on it),
  // paused once a chunk is done until cocotb drops start, so the simulator skips straight
  // to cocotb's next timer. cocotb never waits on a clock edge.
  initial clk = 1'b0;
  always begin
    #PERIOD clk = 1'b1;
    clk <= 1'b0;
    wait (!(done && start));
  end
`endif
  initial done = 1'b0;
  initial hword = {HWS{1'b0}};
  initial playing = 1'b0;
  initial filling = 1'b0;
  initial junking = 1'b0;
  initial junk_rst = 1'b0;

  always @(posedge clk) begin
    unit_rst <= rst;
    host_q <= hword;
  end

  // The file handles ($fopen, $fread, DPI calls) are assigned blocking: simulation-only
  // I/O, read back in the same clock.
  /* verilator lint_off BLKSEQ */
  always @(posedge clk) begin
    if (unit_rst) begin
      run <= 1'b0;
      done <= 1'b0;
      timed_out <= 1'b0;
      in_valid <= 1'b0;
      out_ready <= 1'b0;
      n_in <= {AW{1'b0}};
      n_out <= {AW{1'b0}};
      cycles <= 48'd0;
      playing <= 1'b0;
      hword <= {HWS{1'b0}};
    end else if (!run && !playing) begin
      if (start && !done) begin
        if (HOST && setup_mode) begin
          if (count != {AW{1'b0}}) begin
            fd = $fopen("bulk_setup.bin", "rb");
            nread = $fread(hmem, fd, 0, count);
            $fclose(fd);
            playing <= 1'b1;
          end else
            done <= 1'b1;
          rd <= {AW{1'b0}};
        end else if (count != {AW{1'b0}}) begin
`ifdef BUMPRTL_BULK_DPI
          nread = bulk_dpi_open("bulk_in.bin", count, IW, "bulk_out.bin", OW);
`else
          fd = $fopen("bulk_in.bin", "rb");
          nread = $fread(stim, fd, 0, count);
          $fclose(fd);
          fd = $fopen("bulk_out.bin", "wb");
`endif
          run <= 1'b1;
        end else if (reset_prefix != 32'd0)
          run <= 1'b1;                   // the reset prefix alone (count = 0)
        else
          done <= 1'b1;
        rd <= {AW{1'b0}};
        n_in <= {AW{1'b0}};
        n_out <= {AW{1'b0}};
        cycles <= 48'd0;
        idle <= 32'd0;
        timed_out <= 1'b0;
        gap_rng <= (gap_seed == 32'd0) ? 32'd1 : gap_seed;
        bp_rng <= (bp_seed == 32'd0) ? 32'd1 : bp_seed;
        filling <= fill_hold != 32'd0;
        fill_n <= 32'd0;
        junking <= reset_prefix != 32'd0;
        junk_n <= 32'd0;
        junk_rst <= 1'b0;
      end else if (!start)
        done <= 1'b0;
    end else if (playing) begin
      if (rd != count) begin
        /* verilator lint_off WIDTHTRUNC */  // one unused word without host ports
        hword <= hmem[rd[AW-2:0]];
        /* verilator lint_on WIDTHTRUNC */
        rd <= rd + 1'b1;
      end else begin
        hword <= {HWS{1'b0}};
        playing <= 1'b0;
        done <= 1'b1;
      end
    end else if (junking) begin
      // the reset prefix: junk pixels (every bit 1) taken while the sink stalls, then one
      // cycle of reset with them in flight; none of them may come out
      out_ready <= 1'b0;
      if (junk_rst) begin
        junk_rst <= 1'b0;
        junking <= 1'b0;
        if (count == {AW{1'b0}}) begin   // the prefix alone: done
          run <= 1'b0;
          done <= 1'b1;
        end
      end else if (junk_n == reset_prefix) begin
        in_valid <= 1'b0;
        junk_rst <= 1'b1;
      end else begin
        in_valid <= 1'b1;
        in_payload <= {IW{1'b1}};
        junk_n <= junk_n + 32'd1;
      end
    end else begin
      cycles <= cycles + 48'd1;
      gap_rng <= gap_next;
      bp_rng <= bp_next;
      if (take)
        n_in <= n_in + 1'b1;
      if (!in_valid || take) begin
        if (rd != count && !gap) begin
          in_valid <= 1'b1;
`ifdef BUMPRTL_BULK_DPI
          bulk_dpi_get(rd, word);
          in_payload <= word;
`else
          in_payload <= stim[rd[AW-2:0]];
`endif
          rd <= rd + 1'b1;
        end else
          in_valid <= 1'b0;
      end
      if (filling) begin
        fill_n <= (!in_ready || (rd == count && !in_valid)) ? fill_n + 32'd1 : 32'd0;
        if (fill_n == fill_hold)
          filling <= 1'b0;
      end
      out_ready <= !stall && !filling;
      if (give) begin
`ifdef BUMPRTL_BULK_DPI
        bulk_dpi_put(out_payload);
`else
        $fwrite(fd, "%u", out_payload);
`endif
        n_out <= n_out + 1'b1;
        idle <= 32'd0;
        if (n_out + 1'b1 == count) begin
          run <= 1'b0;
          done <= 1'b1;
          in_valid <= 1'b0;
          out_ready <= 1'b0;
`ifdef BUMPRTL_BULK_DPI
          bulk_dpi_close();
`else
          $fclose(fd);
`endif
        end
      end else if (idle == idle_limit) begin
        run <= 1'b0;
        done <= 1'b1;
        timed_out <= 1'b1;
        in_valid <= 1'b0;
        out_ready <= 1'b0;
`ifdef BUMPRTL_BULK_DPI
        bulk_dpi_close();
`else
        $fclose(fd);
`endif
      end else
        idle <= idle + 32'd1;
    end
  end
  /* verilator lint_on BLKSEQ */
endmodule
