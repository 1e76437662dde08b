!> Accumulations over several contacts (METHOD.md 9; docs/method.md, "Accumulation over
!> several contacts"): a bounce series that alternates between contacts (a light body between
!> a wall and a heavier body pushed onto it) converges geometrically in time: the durations of
!> successive passages shrink by the cycle map's dominant rate. Both engines record each event
!> point that had impacts (which rows took impulses, every row's normal velocity after them);
!> when the last points repeat a pattern of period p, the last three periods' durations
!> shrink by one ratio rho < 1 (to cycle_fit) and the rows' normal velocities do not grow,
!> the rest of the series lasts dt rho / (1 - rho), dt the last period. Once that is below the
!> cut (cycle_cut of the step, or the clock's resolution) the engine closes every row of the
!> cycle now (the bodies they join move as one, at rest when joined to the ground) and logs
!> their rests at the limit time. The velocities need not shrink at the time's rate: a light
!> body squeezed onto a wall by a heavy one rattles in a gap that closes faster than their
!> speeds fall (the issue 19 scene: durations 0.57 per cycle, speeds 0.90), and all of them
!> reach rest at the limit. One contact's series is summed exactly by the Zeno rule instead.
module impact1d_accumulation
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_clusters, only: uf_join, group_means
  implicit none
  private
  public :: cycle_history_type, cycle_points, join_cycle

  !> The longest period looked for (event points per cycle), and the history kept.
  integer, parameter :: cycle_points = 12, kept = 3 * cycle_points
  !> Relative misfit allowed between the last two periods' rates.
  real(wp), parameter :: cycle_fit = 1.0e-3_wp
  !> The remaining series is cut once shorter than this fraction of the step (or the clock's
  !> resolution): the issue 19 scene (a light body squeezed onto a wall) chattered at 1e-13
  !> m/s some 1e-11 s before its limit; cut here its rests land within 2e-16 s of the exact
  !> limit at dt = 0.01, 1e-3 and 1e-4, and no series the two-body reference follows to
  !> 1e-12 s (tests/test_reference.py) is cut before it ends.
  real(wp), parameter :: cycle_cut = 1.0e-11_wp

  type :: cycle_history_type
    integer :: n = 0                               !< points held (up to kept)
    integer :: newest = 0                          !< column of the newest point (a ring)
    real(wp) :: t(kept) = 0.0_wp
    !> Each point's rows hit as one number (a sum of the rows' own odd multipliers): patterns
    !> are compared by these first, the rows themselves only where they agree.
    integer(int64) :: signature(kept) = 0
    logical, allocatable :: hit(:, :)              !< (nr, kept) rows that took an impulse
    real(wp), allocatable :: u(:, :)               !< (nr, kept) normal velocities after
  contains
    procedure :: reserve
    procedure :: forget
    procedure :: record
    procedure :: find_cycle
  end type cycle_history_type

contains

  !> Room for a run of n_rows rows; nothing recorded.
  pure subroutine reserve(self, n_rows)
    class(cycle_history_type), intent(inout) :: self
    integer, intent(in) :: n_rows
    if (allocated(self%hit)) deallocate(self%hit, self%u)
    allocate(self%hit(n_rows, kept), self%u(n_rows, kept))
    self%n = 0
  end subroutine reserve

  !> A cycle ended (its rows closed): nothing of it counts for the next one.
  pure subroutine forget(self)
    class(cycle_history_type), intent(inout) :: self
    self%n = 0
  end subroutine forget

  !> An event point at t whose impulses hit the rows marked, leaving normal velocities u.
  pure subroutine record(self, t, hit, u)
    class(cycle_history_type), intent(inout) :: self
    real(wp), intent(in) :: t
    logical, intent(in) :: hit(:)
    real(wp), intent(in) :: u(:)
    self%newest = modulo(self%newest, kept) + 1
    self%n = min(self%n + 1, kept)
    self%t(self%newest) = t
    self%hit(:, self%newest) = hit
    self%u(:, self%newest) = u
    self%signature(self%newest) = signature_of(hit)
  end subroutine record

  !> The rows hit as one number: distinct sets rarely agree (and find_cycle compares the
  !> rows themselves where they do).
  pure integer(int64) function signature_of(hit) result(h)
    logical, intent(in) :: hit(:)
    integer :: k
    h = 0_int64
    do k = 1, size(hit)
      if (hit(k)) h = ieor(h, int(k, int64) * 2654435761_int64 + 1_int64)
    end do
  end function signature_of

  !> The column of the point `back` points before the newest.
  pure integer function at(self, back)
    class(cycle_history_type), intent(in) :: self
    integer, intent(in) :: back
    at = modulo(self%newest - 1 - back, kept) + 1
  end function at

  !> The shortest period p whose pattern the last points repeat with a geometric decay
  !> (module header); found when the rest of its series lasts less than the cut (cycle_cut
  !> of dt, or min_time): its rows and the time left to the limit (remaining).
  pure subroutine find_cycle(self, row_body, dt, min_time, rows, remaining, found)
    class(cycle_history_type), intent(in) :: self
    integer, intent(in) :: row_body(:, :)     !< (2, nr) the rows' ends (0 the ground)
    real(wp), intent(in) :: dt, min_time
    logical, intent(out) :: rows(:)
    real(wp), intent(out) :: remaining
    logical, intent(out) :: found
    integer :: p, j, now, then
    real(wp) :: rho, rho_before, period, period_before
    logical :: repeats
    found = .false.
    remaining = huge(1.0_wp)
    rows = .false.
    ! A series whose remaining time is below the cut has passages far shorter than it: the
    ! common case (points a step or more apart) costs one test (a ratio rho below 1e-3 per
    ! period is let through to the next points).
    if (self%n < 3) return
    if (self%t(at(self, 0)) - self%t(at(self, 1)) > 1.0e3_wp * max(cycle_cut * dt, min_time)) return
    do p = 1, cycle_points
      if (self%n < 2 * p + 1) return
      ! (the signatures first: most periods fail on the newest point at once; then the rows,
      ! the first point that differs ending the comparison)
      repeats = .true.
      do j = 0, p
        repeats = self%signature(at(self, j)) == self%signature(at(self, j + p))
        if (.not. repeats) exit
      end do
      if (.not. repeats) cycle
      do j = 0, p
        repeats = all(self%hit(:, at(self, j)) .eqv. self%hit(:, at(self, j + p)))
        if (.not. repeats) exit
      end do
      if (.not. repeats) cycle
      rows = .false.
      do j = 0, p - 1
        rows = rows .or. self%hit(:, at(self, j))
      end do
      ! One contact's series, or several independent ones at the same instants (two bodies
      ! each settling on its own wall): the Zeno rule sums each exactly.
      ! (the longer periods that repeat are multiples of this one, over the same rows)
      if (count(rows) < 2 .or. .not. connected(row_body, rows)) return
      ! The durations of the last three periods shrink by one ratio (the cycle map's
      ! dominant rate), and the rows' normal velocities do not grow.
      if (self%n < 3 * p + 1) return
      now = at(self, 0)
      then = at(self, p)
      period = self%t(now) - self%t(then)
      period_before = self%t(then) - self%t(at(self, 2 * p))
      if (period <= 0.0_wp .or. period_before <= 0.0_wp) cycle
      rho = period / period_before
      rho_before = period_before / (self%t(at(self, 2 * p)) - self%t(at(self, 3 * p)))
      if (.not. (rho > 0.0_wp .and. rho < 1.0_wp) .or. abs(rho - rho_before) > cycle_fit * rho) cycle
      if (sum(self%u(:, now)**2, mask=rows) > sum(self%u(:, then)**2, mask=rows)) cycle
      remaining = period * rho / (1.0_wp - rho)
      found = remaining < max(cycle_cut * dt, min_time)
      return
    end do
  end subroutine find_cycle

  !> Whether the marked rows are joined through shared bodies (the ground joins nothing).
  pure logical function connected(row_body, rows)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: rows(:)
    logical :: reached(size(rows)), grew
    integer :: k, j
    reached = .false.
    reached(findloc(rows, .true., 1)) = .true.
    grew = .true.
    do while (grew)
      grew = .false.
      do k = 1, size(rows)
        if (.not. rows(k) .or. reached(k)) cycle
        do j = 1, size(rows)
          if (.not. reached(j)) cycle
          if (any(row_body(:, k) > 0 .and. (row_body(:, k) == row_body(1, j) .or. row_body(:, k) == row_body(2, j)))) then
            reached(k) = .true.
            grew = .true.
            exit
          end if
        end do
      end do
    end do
    connected = all(reached .or. .not. rows)
  end function connected

  !> The velocities v (N) after a cycle's rows close: the bodies those rows join move as one
  !> with their momentum (at rest when joined to the ground): row k's ends row_body(:, k).
  subroutine join_cycle(row_body, rows, mass, v)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: rows(:)
    real(wp), intent(in) :: mass(:)
    real(wp), intent(inout) :: v(:)
    integer :: root(0:size(mass)), k, i
    real(wp) :: group_mass(0:size(mass)), group_sum(0:size(mass))
    logical :: joined
    root = [(i, i = 0, size(mass))]
    do k = 1, size(rows)
      if (rows(k)) joined = uf_join(root, row_body(1, k), row_body(2, k))
    end do
    call group_means(root, mass, v, group_mass, group_sum)
  end subroutine join_cycle
end module impact1d_accumulation
