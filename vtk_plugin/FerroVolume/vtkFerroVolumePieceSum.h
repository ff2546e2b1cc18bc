// vtkFerroVolumePieceSum: the additive blend mode over the processes of a parallel run that
// each draw one piece of a volume (vtkFerroVolumeMapper::DistributedSum, which ParaView sets
// under MPI). Compositing the processes' frames with IceT's 8-bit "over" cannot add two sums
// (it would overflow past 1), so the frames are added here instead: every process sends its
// frame's grey sums to the lowest process that drew a frame, which draws min(1, the sum),
// opaque where any piece's ray had samples; the others draw nothing. The sum is a collective
// operation: every process calls Begin and Finish around each render of the mapper, and Add
// in between once it has a frame (a process without one, after an error or with nothing
// visible, takes part with nothing in Finish). Internal to the FerroVolume module (not
// wrapped).
#ifndef vtkFerroVolumePieceSum_h
#define vtkFerroVolumePieceSum_h

#include <string>
#include <vector>

class vtkFerroVolumeReport;
class vtkTextureObject;

class vtkFerroVolumePieceSum
{
public:
  // Starts a render: `active` when the frames of this render are to be summed across the
  // global controller's processes (ignored with fewer than 2 processes).
  void Begin(bool active);
  // Whether this render's frame still has to be added.
  bool Pending() const { return this->Waiting; }
  // Adds this process's frame (its colour texture: premultiplied RGBA8, w x h), and
  // replaces it by the sum on the process that draws it. `draw`: whether this process
  // composites its frame into its window. False with the report's error when the texture
  // could not be read or written (the sum went on without this frame; nothing to draw); true
  // with a warning (once) when the processes' frames differ in size (each then draws its
  // own, which "over" composites as before).
  bool Add(vtkTextureObject* color, int w, int h, bool& draw, vtkFerroVolumeReport& report);
  // Ends the render: takes part with nothing when Add was not called.
  void Finish();

private:
  enum class Outcome
  {
    Skip,   // another process draws the sum
    Draw,   // this process draws the sum, now in `rgba`
    DrawOwn // the frames differ in size: every process draws its own
  };
  // The collective part: `rgba` this process's frame (empty: none).
  Outcome Reduce(std::vector<unsigned char>& rgba, int w, int h);

  bool Waiting = false;
  std::vector<unsigned char> Pixels;
};

#endif
