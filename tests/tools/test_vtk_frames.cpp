// VTK frames: what write_vtp / write_piece / write_pvtp / PvdSeries write must read back through
// VTK's own readers bit for bit.
#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "basalt/io/vtk_frame_writer.hpp"
#include "basalt/io/vtk_frames.hpp"
#include "basalt/io/vtk_polydata.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;

namespace {

// A small checkpoint with values that do not round-trip through float (so float storage would fail).
Checkpoint make_checkpoint(int n, std::int64_t first_id) {
  Checkpoint c;
  for (int i = 0; i < n; ++i) {
    const double x = 0.1 * i + 1.0 / 3.0;
    c.geometry.add_particle(first_id + 3 * i, {x, std::sin(x) * 7.0, 1e-7 * i - 2.5}, 0.2 + 0.01 * (i % 7),
                            i % 3);
    c.geometry.mass.push_back(4.0 / 3.0 * M_PI * std::pow(0.2 + 0.01 * (i % 7), 3));
    c.velocity.push_back({0.01 * i, -0.02 * i, 1.0 / (i + 1.0)});
  }
  c.step = 1200;
  c.time = 1.2000000000000002;
  c.dt = 1e-3;
  return c;
}

vtkDataArray* array(vtkPolyData* pd, const char* name) {
  vtkDataArray* a = pd->GetPointData()->GetArray(name);
  EXPECT_NE(a, nullptr) << "missing point array " << name;
  return a;
}

void expect_same_particles(vtkPolyData* pd, const Checkpoint& c, vtkIdType offset,
                           const std::vector<Vec3>& disp) {
  const auto n = static_cast<vtkIdType>(c.size());
  auto* id = array(pd, "id");
  auto* radius = array(pd, "radius");
  auto* tag = array(pd, "tag");
  auto* mass = array(pd, "mass");
  auto* velocity = array(pd, "velocity");
  auto* speed = array(pd, "speed");
  auto* displacement = disp.empty() ? nullptr : array(pd, "displacement");
  if (!id || !radius || !tag || !mass || !velocity || !speed || (!disp.empty() && !displacement)) return;
  EXPECT_EQ(velocity->GetNumberOfComponents(), 3);
  EXPECT_EQ(id->GetDataTypeSize(), 8);  // ids stay 64-bit integers
  EXPECT_TRUE(id->GetDataType() == VTK_LONG_LONG || id->GetDataType() == VTK_LONG);
  for (vtkIdType i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    double p[3];
    pd->GetPoint(offset + i, p);
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(p[d], c.geometry.position[k][d]) << "particle " << i;
      EXPECT_EQ(velocity->GetComponent(offset + i, d), c.velocity[k][d]);
      if (displacement) {
        EXPECT_EQ(displacement->GetComponent(offset + i, d), disp[k][d]);
      }
    }
    EXPECT_EQ(static_cast<std::int64_t>(id->GetTuple1(offset + i)), c.geometry.id[k]);
    EXPECT_EQ(radius->GetTuple1(offset + i), c.geometry.radius[k]);
    EXPECT_EQ(tag->GetTuple1(offset + i), c.geometry.tag[k]);
    EXPECT_EQ(mass->GetTuple1(offset + i), c.geometry.mass[k]);
    const auto& v = c.velocity[k];
    EXPECT_DOUBLE_EQ(speed->GetTuple1(offset + i), std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
  }
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(VtkFrames, VtpReadsBackExactlyThroughVtkReader) {
  const fs::path dir = basalt::test::scratch_dir("vtk-vtp");
  const Checkpoint c = make_checkpoint(257, 10);
  std::vector<Vec3> disp(c.size());
  for (std::size_t i = 0; i < disp.size(); ++i) disp[i] = {1e-9 * i, -0.5, 0.25 * i};
  write_vtp(c, dir / "frame.vtp", disp);
  EXPECT_FALSE(fs::exists(dir / "frame.vtp.partial"));

  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName((dir / "frame.vtp").c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  ASSERT_EQ(pd->GetNumberOfPoints(), 257);
  EXPECT_EQ(pd->GetNumberOfVerts(), 257);  // one vertex cell per particle
  expect_same_particles(pd, c, 0, disp);
  const FrameInfo info = info_of(*pd);
  EXPECT_TRUE(info.has_clock);
  EXPECT_EQ(info.step, 1200);
  EXPECT_EQ(info.time, c.time);
  EXPECT_EQ(info.units.length, "mm");
  // Binary appended data, as ParaView reads fastest.
  EXPECT_NE(slurp(dir / "frame.vtp").find("<AppendedData encoding=\"raw\">"), std::string::npos);
}

TEST(VtkFrames, PiecesAndPvtpReadBackThroughParallelReader) {
  const fs::path dir = basalt::test::scratch_dir("vtk-pvtp");
  // Three writers, each with its own piece (as three I/O ranks would), one of them empty.
  const Checkpoint a = make_checkpoint(100, 0), b = make_checkpoint(0, 1000), c = make_checkpoint(37, 5000);
  const Checkpoint* pieces[] = {&a, &b, &c};
  const auto layout = layout_of(arrays_of(a));
  for (int p = 0; p < 3; ++p) {
    const fs::path f = write_piece(dir, 1200, p, 3, arrays_of(*pieces[p]), info_of(*pieces[p]), layout);
    EXPECT_EQ(f, piece_path(dir, 1200, p));
    EXPECT_TRUE(fs::exists(f));
  }
  const fs::path pvtp = write_pvtp(dir, 1200, 3, layout);
  EXPECT_EQ(pvtp, dir / "frame_00001200.pvtp");

  auto reader = vtkSmartPointer<vtkXMLPPolyDataReader>::New();
  reader->SetFileName(pvtp.c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  ASSERT_EQ(pd->GetNumberOfPoints(), 137);
  expect_same_particles(pd, a, 0, {});
  expect_same_particles(pd, c, 100, {});

  // Through Basalt's own reader too (as basalt-view reads a .pvtp).
  auto again = read_polydata(pvtp);
  EXPECT_EQ(again->GetNumberOfPoints(), 137);
}

TEST(VtkFrames, PieceIndexOutOfRangeIsRefused) {
  const fs::path dir = basalt::test::scratch_dir("vtk-range");
  const Checkpoint a = make_checkpoint(3, 0);
  const auto layout = layout_of(arrays_of(a));
  EXPECT_THROW(write_piece(dir, 0, 2, 2, arrays_of(a), info_of(a), layout), std::invalid_argument);
  EXPECT_THROW(write_piece(dir, 0, -1, 2, arrays_of(a), info_of(a), layout), std::invalid_argument);
  // A non-empty piece without the frame's velocity array would make ParaView refuse the frame.
  EXPECT_THROW(write_piece(dir, 0, 0, 2, arrays_of(a.geometry), info_of(a), layout), std::invalid_argument);
}

TEST(VtkFrames, MismatchedArrayLengthsAreRefused) {
  Checkpoint a = make_checkpoint(5, 0);
  a.velocity.pop_back();
  EXPECT_THROW(write_vtp(a, basalt::test::scratch_dir("vtk-len") / "x.vtp"), std::invalid_argument);
}

TEST(VtkFrames, UnwritableFolderNamesTheFileAndLeavesNothing) {
  const fs::path dir = basalt::test::scratch_dir("vtk-unwritable");
  const fs::path target = dir / "no-such-folder" / "frame.vtp";
  try {
    write_vtp(make_checkpoint(4, 0), target);
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(target));
}

TEST(VtkFrames, ReadingGarbageNamesTheFile) {
  const fs::path dir = basalt::test::scratch_dir("vtk-garbage");
  std::ofstream(dir / "bad.vtp") << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\"><PolyData><Piece";
  try {
    read_polydata(dir / "bad.vtp");
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.vtp"), std::string::npos) << e.what();
  }
  try {
    read_polydata(dir / "missing.vtp");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.vtp"), std::string::npos);
  }
}

TEST(VtkFrames, PvdSeriesRewritesAtomicallyAndResumes) {
  const fs::path dir = basalt::test::scratch_dir("vtk-pvd");
  {
    PvdSeries s(dir / "run.pvd");
    s.add(0.1, dir / "frame_00000100.pvtp");  // absolute: stored relative to the .pvd
    s.add(0.2, "frame_00000200.pvtp");
    s.add(0.30000000000000004, "a&b.vtp");
  }
  const std::string text = slurp(dir / "run.pvd");
  EXPECT_NE(text.find("timestep=\"0.10000000000000001\" group=\"\" part=\"0\" file=\"frame_00000100.pvtp\""),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("file=\"a&amp;b.vtp\""), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "run.pvd.partial"));

  PvdSeries resumed(dir / "run.pvd", true);
  ASSERT_EQ(resumed.entries().size(), 3u);
  EXPECT_EQ(resumed.entries()[2].time, 0.30000000000000004);
  EXPECT_EQ(resumed.entries()[2].file, "a&b.vtp");
  resumed.truncate_after(0.15);
  EXPECT_EQ(PvdSeries(dir / "run.pvd", true).entries().size(), 1u);

  std::ofstream(dir / "bad.pvd") << "<VTKFile>\n<Collection>\n<DataSet timestep=\"x1\" file=\"f.vtp\"/>\n";
  try {
    PvdSeries bad(dir / "bad.pvd", true);
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
}

namespace {
FramePiece frame_piece(int source_rank, int n, std::int64_t first_id) {
  FramePiece p;
  p.source_rank = source_rank;
  for (int i = 0; i < n; ++i) {
    p.id.push_back(first_id + i);
    p.position.push_back({0.5 * i, 1.0 / 3.0 * source_rank, 0.1 * i});
    p.velocity.push_back({0, 0, 0.01 * i});
    p.radius.push_back(0.25);
    p.mass.push_back(0.1);
    p.tag.push_back(source_rank);
  }
  return p;
}
}  // namespace

TEST(VtkFrames, FrameWriterWritesPiecesPvtpAndResumableSeries) {
  // basalt-run's frame writer (the I/O ranks', and compute rank 0's with --io-ranks 0).
  const fs::path dir = basalt::test::scratch_dir("vtk-ioranks");
  // Two writers (I/O ranks), each serving two compute ranks; the second writer's share is empty at step 200.
  VtkFrameWriter w0 = make_vtk_frame_writer(Units{}), w1 = make_vtk_frame_writer(Units{});
  const std::vector<FramePiece> a{frame_piece(0, 10, 0), frame_piece(1, 5, 100)};
  const std::vector<FramePiece> b{frame_piece(2, 7, 200), frame_piece(3, 0, 300)};
  EXPECT_GT(w1(b, 100, 0.1, 1, 2, dir), 0u);
  EXPECT_GT(w0(a, 100, 0.1, 0, 2, dir), 0u);
  EXPECT_GT(w1({}, 200, 0.2, 1, 2, dir), 0u);
  EXPECT_GT(w0(a, 200, 0.2, 0, 2, dir), 0u);

  auto reader = vtkSmartPointer<vtkXMLPPolyDataReader>::New();
  reader->SetFileName((dir / "frame_00000100.pvtp").c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  ASSERT_EQ(pd->GetNumberOfPoints(), 22);
  auto* id = array(pd, "id");
  ASSERT_NE(id, nullptr);
  EXPECT_EQ(id->GetTuple1(10), 100);  // second compute rank of writer 0
  EXPECT_EQ(id->GetTuple1(15), 200);  // first particle of writer 1
  EXPECT_EQ(pd->GetPoint(16)[1], 1.0 / 3.0 * 2);
  for (const char* name : {"radius", "tag", "mass", "velocity", "speed"})
    EXPECT_NE(array(pd, name), nullptr) << name;
  auto step200 = read_polydata(dir / "frame_00000200.pvtp");
  EXPECT_EQ(step200->GetNumberOfPoints(), 15);  // writer 1 wrote an empty piece
  EXPECT_EQ(info_of(*step200).step, 200);
  EXPECT_EQ(info_of(*step200).time, 0.2);

  ASSERT_EQ(PvdSeries(dir / "frames.pvd", true).entries().size(), 2u);
  EXPECT_EQ(PvdSeries(dir / "frames.pvd", true).entries()[1].file, "frame_00000200.pvtp");
  // A restart from the checkpoint at t = 0.1 (a new writer) drops the later frame and writes it again,
  // rather than listing it twice.
  VtkFrameWriter restarted = make_vtk_frame_writer(Units{}, 0.1);
  restarted(a, 200, 0.2, 0, 1, dir);
  const PvdSeries after(dir / "frames.pvd", true);
  ASSERT_EQ(after.entries().size(), 2u);
  EXPECT_EQ(after.entries()[0].time, 0.1);
  EXPECT_EQ(after.entries()[1].time, 0.2);
  // A new run (no restart) starts a new series.
  VtkFrameWriter fresh = make_vtk_frame_writer(Units{});
  fresh(a, 300, 0.3, 0, 1, dir);
  ASSERT_EQ(PvdSeries(dir / "frames.pvd", true).entries().size(), 1u);
}
