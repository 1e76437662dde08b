!> What the event log has said and still owes (METHOD.md 6): which contacts rest, which
!> bodies are at rest, rests logged at a bounce series' accumulation time, releases held
!> back until time moves on (a contact that closes again at the same instant never
!> opened).
module impact1d_event_log
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type, tutorial_bodies
  use impact1d_output, only: sink_type, run_stats, class_rest, class_release, class_stick, class_slip, count_event, &
    class_pair_stick
  use impact1d_yardsticks, only: same_instant
  use impact1d_accumulation, only: cycle_history_type
  implicit none
  private
  public :: event_log_type, log_event

  !> The log's bookkeeping between event points; the per-row (nr) and per-body (N) arrays
  !> allocated by allocate_log.
  type :: event_log_type
    logical, allocatable :: in_contact(:)          !< (nr) row k has been logged resting
    logical, allocatable :: at_rest(:)             !< (N) body i has been logged at rest (stick)
    !> (nr) A rest after an accumulation of impacts, logged when its time comes.
    real(wp), allocatable :: pending_rest(:)
    !> (nr) A release waiting for time to move on (see begin_rest), with the velocities it
    !> reports (its pair's: log_event).
    real(wp), allocatable :: release_time(:)
    real(wp), allocatable :: release_v(:, :)       !< (2, nr)
    !> (N) When impulses last moved each body off its rest (see the stick log at the event point).
    real(wp), allocatable :: rest_lost_time(:)
    !> The event points with impacts lately (an accumulation over several contacts).
    type(cycle_history_type) :: cycles
  contains
    procedure :: allocate_log
    procedure :: flush_pending_rest
    procedure :: flush_releases
    procedure :: begin_rest
  end type event_log_type

contains

  !> Nothing logged yet, for n_rows rows and n bodies.
  pure subroutine allocate_log(self, n_rows, n)
    class(event_log_type), intent(inout) :: self
    integer, intent(in) :: n_rows, n
    allocate(self%in_contact(n_rows), self%pending_rest(n_rows), self%release_time(n_rows), &
      self%release_v(2, n_rows), self%at_rest(n), self%rest_lost_time(n))
    self%in_contact = .false.
    self%pending_rest = huge(1.0_wp)
    self%release_time = huge(1.0_wp)
    self%release_v = 0.0_wp
    self%at_rest = .false.
    self%rest_lost_time = -huge(1.0_wp)
    call self%cycles%reserve(n_rows)
  end subroutine allocate_log

  !> Event (class, index) at t, counted and sent to the sink with the velocities of the
  !> pair it reports (docs/nbody-plan.md, "The event record"): with one or two bodies that
  !> is (1, 2), or (1, 0) with one body, whatever the event (a wall's impact reports both
  !> bodies). v_before, v_after: the N bodies' velocities, or the pair's two (a release's,
  !> kept by the log).
  subroutine log_event(scene, sink, stats, t, class, index, v_before, v_after)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp), intent(in) :: t
    integer, intent(in) :: class, index
    real(wp), intent(in) :: v_before(:), v_after(:)
    real(wp) :: v(4)
    integer :: ends(2)
    call count_event(stats, class, index)
    v = 0.0_wp
    if (scene%n_bodies > tutorial_bodies) then
      ! N bodies: the event's own pair, the row's ends or (body, 0).
      ends = [index, 0]
      if (class /= class_stick .and. class /= class_slip) ends = scene%row_body(:, index)
      if (class >= class_pair_stick) ends = scene%friction_body(:, index - size(scene%row_name))
      call pair_velocities(ends, v_before, v(1:2))
      call pair_velocities(ends, v_after, v(3:4))
      call sink%put_event(t, class, index, ends(1), ends(2), v)
      return
    end if
    v(1) = v_before(1)
    v(3) = v_after(1)
    if (scene%n_bodies == 2) then
      v(2) = v_before(2)
      v(4) = v_after(2)
    end if
    call sink%put_event(t, class, index, 1, merge(2, 0, scene%n_bodies == 2), v)
  end subroutine log_event

  !> The velocities of a pair's ends (0 for the ground) from the N bodies' velocities v, or
  !> from v itself when it holds the pair's two (a release's, kept by the log).
  pure subroutine pair_velocities(ends, v, pair)
    integer, intent(in) :: ends(2)
    real(wp), intent(in) :: v(:)
    real(wp), intent(out) :: pair(2)
    integer :: e
    if (size(v) == 2) then
      pair = v
      return
    end if
    pair = 0.0_wp
    do e = 1, 2
      if (ends(e) > 0) pair(e) = v(ends(e))
    end do
  end subroutine pair_velocities

  !> Rest after an accumulation of impacts is logged at the accumulation time (t, velocities v).
  subroutine flush_pending_rest(self, scene, t, v, sink, stats)
    class(event_log_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(:)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    integer :: k
    do k = 1, size(self%pending_rest)
      if (self%pending_rest(k) <= t) then
        call log_event(scene, sink, stats, t, class_rest, k, v, v)
        self%pending_rest(k) = huge(1.0_wp)
      end if
    end do
  end subroutine flush_pending_rest

  !> Log the releases decided at an instant before t (all of them with everything).
  subroutine flush_releases(self, scene, t, everything, sink, stats)
    class(event_log_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t
    logical, intent(in) :: everything
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    integer :: k
    do k = 1, size(self%release_time)
      if (self%release_time(k) == huge(1.0_wp)) cycle
      if (.not. everything .and. same_instant(scene, t, self%release_time(k))) cycle
      call log_event(scene, sink, stats, self%release_time(k), class_release, k, self%release_v(:, k), &
        self%release_v(:, k))
      self%release_time(k) = huge(1.0_wp)
    end do
  end subroutine flush_releases

  !> Contact k starts to rest at t (velocities v), logged at `when` (now, or a series'
  !> accumulation time). Nothing is logged if it already rests, or if it was released at
  !> this same instant.
  subroutine begin_rest(self, scene, k, t, when, v, sink, stats)
    class(event_log_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: t, when, v(:)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    if (self%in_contact(k)) return
    self%in_contact(k) = .true.
    if (self%release_time(k) < huge(1.0_wp)) then
      if (same_instant(scene, t, self%release_time(k))) then
        self%release_time(k) = huge(1.0_wp)
        return
      end if
    end if
    ! Releases from earlier instants go first; one at this instant may still cancel.
    call self%flush_releases(scene, t, .false., sink, stats)
    if (when > t) then
      self%pending_rest(k) = when
    else
      call log_event(scene, sink, stats, t, class_rest, k, v, v)
    end if
  end subroutine begin_rest
end module impact1d_event_log
