// A minimal Verilog top around the bump-mapping pipeline (docs/examples/README.md).
//
// The pipeline of the default scene, emitted with named ports and the map left to the host
// write port:
//   bumprtl emit pipeline --scene default --ports named --load port
// (or by `bumprtl vectors ... --load port`, which writes the same design). Its ports and
// widths are those of bumprtl_pipeline.json ("named_ports"); another scene or other widths
// change them, and this file with them.
//
// bump_top has the pipeline's clock, reset and two streams; inside, a loader copies the
// bump map from a ROM ($readmemh of bumprtl_pipeline_map.hex, the file emit writes) through
// the host write port after reset, one word a clock, and holds in_ready low until the map
// is in (docs/integration.md, "Loading the maps": after reset, before the first pixel).
// The ROM stands in for whatever brings the map in your system (a host bus, a flash reader).
module bump_top #(
  parameter MAP_FILE = "bumprtl_pipeline_map.hex",
  parameter integer MAP_DEPTH = 4096,           // memory_images.map.depth
  parameter integer MAP_WIDTH = 28,             // memory_images.map.width
  parameter integer ADDR_BITS = 12              // width of map_w_addr
) (
  input  wire        clk,
  input  wire        rst,                       // synchronous, active high
  // pixels in: texel (u, v), N, L, H as binary angles, a tag
  input  wire        in_valid,
  output wire        in_ready,
  input  wire signed [7:0] in_u,
  input  wire signed [7:0] in_v,
  input  wire [13:0] in_n_phi,
  input  wire [13:0] in_n_theta,
  input  wire [13:0] in_l_phi,
  input  wire [13:0] in_l_theta,
  input  wire [13:0] in_h_phi,
  input  wire [13:0] in_h_theta,
  input  wire [15:0] in_tag,
  // shaded pixels out, in order
  output wire        out_valid,
  input  wire        out_ready,
  output wire [7:0]  out_diffuse,
  output wire [7:0]  out_specular,
  output wire [7:0]  out_color,
  output wire [15:0] out_diffuse_fine,
  output wire [16:0] out_specular_fine,
  output wire [15:0] out_tag
);
  // --- the map loader: read word a, write it at address a one clock later ---------------
  reg [MAP_WIDTH-1:0] map_rom [0:MAP_DEPTH-1];
  initial $readmemh(MAP_FILE, map_rom);

  reg [ADDR_BITS:0]   addr;                     // next word to read; MAP_DEPTH when all read
  reg                 loaded;
  reg                 map_w_en;
  reg [ADDR_BITS-1:0] map_w_addr;
  reg [MAP_WIDTH-1:0] map_w_data;
  always @(posedge clk) begin
    if (rst) begin
      addr <= 0;
      loaded <= 1'b0;
      map_w_en <= 1'b0;
    end else begin
      map_w_en <= !loaded && addr < MAP_DEPTH;
      map_w_addr <= addr[ADDR_BITS-1:0];
      map_w_data <= map_rom[addr[ADDR_BITS-1:0]];
      if (!loaded && addr < MAP_DEPTH)
        addr <= addr + 1'b1;
      else if (!loaded)
        loaded <= 1'b1;                         // the last word is written at this edge
    end
  end

  // --- the pipeline: pixels only once the map is in -------------------------------------
  wire pipe_in_ready;
  assign in_ready = pipe_in_ready && loaded;

  bumprtl_pipeline_named u_bump (
    .clk              (clk),
    .rst              (rst),
    .in_valid         (in_valid && loaded),
    .in_ready         (pipe_in_ready),
    .in_u             (in_u),
    .in_v             (in_v),
    .in_n_phi         (in_n_phi),
    .in_n_theta       (in_n_theta),
    .in_l_phi         (in_l_phi),
    .in_l_theta       (in_l_theta),
    .in_h_phi         (in_h_phi),
    .in_h_theta       (in_h_theta),
    .in_tag           (in_tag),
    .out_valid        (out_valid),
    .out_ready        (out_ready),
    .out_diffuse      (out_diffuse),
    .out_specular     (out_specular),
    .out_color        (out_color),
    .out_diffuse_fine (out_diffuse_fine),
    .out_specular_fine(out_specular_fine),
    .out_tag          (out_tag),
    .map_w_addr       (map_w_addr),
    .map_w_data       (map_w_data),
    .map_w_en         (map_w_en)
  );
endmodule
