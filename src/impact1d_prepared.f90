!> Prepared scenes for the flat API (issue 20 item 1): a scene validated and built once
!> (prepare_scene's scene_type with the run's columns), run again and again by handle.
!> Python keeps one per core form it runs more than once and frees it with the form.
!>
!> The handle is the entry's address: the caller owns the entry (as it owns what any call
!> returns) and the core keeps no table, so nothing is shared between calls but what the
!> caller hands back. Threads: an entry is freed only when no run uses it (Python frees it
!> with its form, which a run holds until it returns), and a run reads its scene
!> (intent(in) through `run`), so concurrent runs of one prepared scene share it safely.
module impact1d_prepared
  use, intrinsic :: iso_c_binding, only: c_intptr_t, c_ptr, c_loc, c_f_pointer
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: prepared_scene, prepared_handle, prepared_entry, prepared_free

  !> What a live entry carries in `tag`: a handle whose memory lacks it names no entry (a
  !> guard against a wrong handle, not a proof: the caller passes only live ones).
  integer, parameter :: live_tag = 20201

  type prepared_scene
    integer :: tag = live_tag
    type(scene_type) :: scene
    integer, allocatable :: columns(:)   !< present_columns of its input
  end type prepared_scene

contains

  !> The handle of an entry allocated by the caller (kept until prepared_free).
  function prepared_handle(entry) result(handle)
    type(prepared_scene), pointer, intent(in) :: entry
    integer(c_intptr_t) :: handle
    handle = transfer(c_loc(entry), handle)
  end function prepared_handle

  !> The entry of `handle`, null for 0 or a handle whose entry is not live.
  function prepared_entry(handle) result(entry)
    integer(c_intptr_t), intent(in) :: handle
    type(prepared_scene), pointer :: entry
    type(c_ptr) :: address
    entry => null()
    if (handle == 0) return
    address = transfer(handle, address)
    call c_f_pointer(address, entry)
    if (entry%tag /= live_tag) entry => null()
  end function prepared_entry

  !> Free the entry of `handle` (0: nothing happens). A handle is freed once: its memory
  !> may be anyone's after.
  subroutine prepared_free(handle)
    integer(c_intptr_t), intent(in) :: handle
    type(prepared_scene), pointer :: entry
    entry => prepared_entry(handle)
    if (.not. associated(entry)) return
    entry%tag = 0
    deallocate(entry)
  end subroutine prepared_free
end module impact1d_prepared
