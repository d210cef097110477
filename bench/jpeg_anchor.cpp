// libjpeg reports errors through a callback that must not return: it longjmps back to the
// setjmp of the call that failed, which turns the failure into a Status.
#include "bench/jpeg_anchor.h"

#include <jpeglib.h>

#include <csetjmp>
#include <cstdlib>
#include <string>

namespace vt::bench {
namespace {

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpeg_error_exit(j_common_ptr cinfo) {
  JpegError* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

Status jpeg_status(ErrorCode code, const JpegError& err) {
  return Error(code, std::string("libjpeg: ") + err.message);
}

}  // namespace

// Heap-held: libjpeg keeps pointers into it (the error manager), so it never moves.
struct JpegPageEncoder::State {
  jpeg_compress_struct c{};
  JpegError err{};
  int size = 0;
  std::vector<uint8_t> tables;
  unsigned char* out = nullptr;  // the page being written (here, not on the stack: see longjmp)
  unsigned long out_size = 0;
  ~State() { jpeg_destroy_compress(&c); }
};

JpegPageEncoder::JpegPageEncoder(std::unique_ptr<State> state) : state_(std::move(state)) {}
JpegPageEncoder::JpegPageEncoder(JpegPageEncoder&&) noexcept = default;
JpegPageEncoder& JpegPageEncoder::operator=(JpegPageEncoder&&) noexcept = default;
JpegPageEncoder::~JpegPageEncoder() = default;

Expected<JpegPageEncoder> JpegPageEncoder::create(const JpegAnchorSettings& settings) {
  auto s = std::make_unique<State>();
  jpeg_compress_struct& c = s->c;
  c.err = jpeg_std_error(&s->err.mgr);
  s->err.mgr.error_exit = jpeg_error_exit;
  s->size = settings.page_size;
  if (setjmp(s->err.jump)) return jpeg_status(ErrorCode::kInternal, s->err);
  jpeg_create_compress(&c);
  c.image_width = JDIMENSION(settings.page_size);
  c.image_height = JDIMENSION(settings.page_size);
  c.input_components = 3;
  c.in_color_space = JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, settings.quality, TRUE);
  const int luma_sampling = settings.subsample ? 2 : 1;
  c.comp_info[0].h_samp_factor = luma_sampling;
  c.comp_info[0].v_samp_factor = luma_sampling;
  jpeg_mem_dest(&c, &s->out, &s->out_size);
  jpeg_write_tables(&c);
  s->tables.assign(s->out, s->out + s->out_size);
  std::free(s->out);
  return JpegPageEncoder(std::move(s));
}

const std::vector<uint8_t>& JpegPageEncoder::tables() const {
  return state_->tables;
}

Status JpegPageEncoder::encode(const uint8_t* rgb, std::vector<uint8_t>& out) {
  State& s = *state_;
  jpeg_compress_struct& c = s.c;
  s.out = nullptr;
  s.out_size = 0;
  if (setjmp(s.err.jump)) {
    jpeg_abort_compress(&c);
    std::free(s.out);
    return jpeg_status(ErrorCode::kInternal, s.err);
  }
  jpeg_mem_dest(&c, &s.out, &s.out_size);
  jpeg_suppress_tables(&c, TRUE);
  jpeg_start_compress(&c, FALSE);  // abbreviated: the tables stay in tables()
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(rgb + size_t(c.next_scanline) * s.size * 3);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  out.assign(s.out, s.out + s.out_size);
  std::free(s.out);
  return Status::Ok();
}

struct JpegPageDecoder::State {
  jpeg_decompress_struct d{};
  JpegError err{};
  int size = 0;
  ~State() { jpeg_destroy_decompress(&d); }
};

JpegPageDecoder::JpegPageDecoder(std::unique_ptr<State> state) : state_(std::move(state)) {}
JpegPageDecoder::JpegPageDecoder(JpegPageDecoder&&) noexcept = default;
JpegPageDecoder& JpegPageDecoder::operator=(JpegPageDecoder&&) noexcept = default;
JpegPageDecoder::~JpegPageDecoder() = default;

Expected<JpegPageDecoder> JpegPageDecoder::create(int page_size, std::span<const uint8_t> tables) {
  auto s = std::make_unique<State>();
  jpeg_decompress_struct& d = s->d;
  d.err = jpeg_std_error(&s->err.mgr);
  s->err.mgr.error_exit = jpeg_error_exit;
  s->size = page_size;
  if (setjmp(s->err.jump)) return jpeg_status(ErrorCode::kCorrupt, s->err);
  jpeg_create_decompress(&d);
  // The tables are copied into `d` and kept for every page read after them.
  jpeg_mem_src(&d, tables.data(), (unsigned long)tables.size());
  if (jpeg_read_header(&d, FALSE) != JPEG_HEADER_TABLES_ONLY) {
    return Error(ErrorCode::kInternal, "libjpeg: the table stream is not tables-only");
  }
  return JpegPageDecoder(std::move(s));
}

Status JpegPageDecoder::decode(std::span<const uint8_t> page, uint8_t* rgb) {
  jpeg_decompress_struct& d = state_->d;
  if (setjmp(state_->err.jump)) {
    jpeg_abort_decompress(&d);
    return jpeg_status(ErrorCode::kCorrupt, state_->err);
  }
  jpeg_mem_src(&d, page.data(), (unsigned long)page.size());
  jpeg_read_header(&d, TRUE);
  d.out_color_space = JCS_RGB;
  jpeg_start_decompress(&d);
  while (d.output_scanline < d.output_height) {
    JSAMPROW row = rgb + size_t(d.output_scanline) * state_->size * 3;
    jpeg_read_scanlines(&d, &row, 1);
  }
  jpeg_finish_decompress(&d);
  return Status::Ok();
}

}  // namespace vt::bench
