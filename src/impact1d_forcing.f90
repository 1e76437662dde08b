!> External forces f_i(t) = constant + table(t) + amp*sin(omega*t + phase), each term present
!> only when the scene names it, so an absent term costs nothing in the stepping loop.
module impact1d_forcing
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes, to_lanes
  implicit none
  private
  public :: table_type, forcing_type

  !> A piecewise-linear force table: strictly increasing times, held constant outside.
  type :: table_type
    real(wp), allocatable :: t(:), f(:)
  end type table_type

  !> Each body's force f_i(t), by term; arrays (N), allocated by allocate_bodies.
  type :: forcing_type
    real(wp), allocatable :: constant(:)        !< (N) constant term, N
    logical, allocatable :: has_table(:)        !< (N) body i has a force table
    logical, allocatable :: has_sine(:)         !< (N) body i has a sine term
    type(table_type), allocatable :: table(:)   !< (N) its table (when has_table)
    real(wp), allocatable :: amp(:), omega(:), phase(:)   !< (N) amp sin(omega t + phase): N, rad/s, rad
    logical :: varies = .false.                 !< some body has a table or a sine (set_varies)
    real(wp) :: constant_lanes(max_lanes) = 0.0_wp  !< (lanes) constant, for force (set_varies)
  contains
    procedure :: allocate_bodies
    procedure :: set_varies
    procedure :: force
    procedure :: force_all
    procedure :: rate
    procedure :: next_breakpoint
    procedure :: is_polynomial
  end type forcing_type

contains

  !> No force on n bodies: every term absent.
  pure subroutine allocate_bodies(self, n)
    class(forcing_type), intent(inout) :: self
    integer, intent(in) :: n
    allocate(self%constant(n), self%has_table(n), self%has_sine(n), self%table(n), self%amp(n), &
      self%omega(n), self%phase(n))
    self%constant = 0.0_wp
    self%has_table = .false.
    self%has_sine = .false.
    self%amp = 0.0_wp
    self%omega = 0.0_wp
    self%phase = 0.0_wp
  end subroutine allocate_bodies

  !> varies: whether the forces change with time, and the constants in lanes (once the
  !> terms are set).
  pure subroutine set_varies(self)
    class(forcing_type), intent(inout) :: self
    self%varies = any(self%has_table) .or. any(self%has_sine)
    call to_lanes(self%constant, self%constant_lanes)
  end subroutine set_varies

  !> Forces on the bodies at time t, in lanes (impact1d_lanes: an idle lane 0). Small, so
  !> that the stepping loop inlines it; tables and sines apart (add_varying).
  pure subroutine force(self, t, f)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp), intent(out) :: f(max_lanes)
    f = self%constant_lanes
    if (self%varies) call add_varying(self, t, f)
  end subroutine force

  !> f += the tables' and sines' terms at t.
  pure subroutine add_varying(self, t, f)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: f(max_lanes)
    integer :: i
    do i = 1, max_lanes      ! (a loop of max_lanes trips the compiler unrolls: N <= max_lanes)
      if (i > size(self%constant)) exit
      call add_body_varying(self, i, t, f(i))
    end do
  end subroutine add_varying

  !> fi += body i's table and sine terms at t (the table's first: the order of the sums).
  pure subroutine add_body_varying(self, i, t, fi)
    class(forcing_type), intent(in) :: self
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: fi
    if (self%has_table(i)) fi = fi + table_value(self%table(i), t)
    if (self%has_sine(i)) fi = fi + self%amp(i) * sin(self%omega(i) * t + self%phase(i))
  end subroutine add_body_varying

  !> Forces on all N bodies at time t (N-long: the N-body engine's; force's sums).
  pure subroutine force_all(self, t, f)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp), contiguous, intent(out) :: f(:)
    integer :: i
    f = self%constant
    if (.not. self%varies) return
    do i = 1, size(f)
      call add_body_varying(self, i, t, f(i))
    end do
  end subroutine force_all

  !> Right derivative df/dt at t, in lanes or N-long (a lane past N 0): tells which way a
  !> force that is exactly at a bound will go.
  pure subroutine rate(self, t, df)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp), intent(out) :: df(:)
    integer :: i, k
    df = 0.0_wp      ! (and an idle lane)
    do i = 1, size(self%constant)
      if (self%has_table(i)) then
        k = segment(self%table(i)%t, t)
        if (k >= 1 .and. k < size(self%table(i)%t)) df(i) = &
          (self%table(i)%f(k + 1) - self%table(i)%f(k)) / (self%table(i)%t(k + 1) - self%table(i)%t(k))
      end if
      if (self%has_sine(i)) df(i) = df(i) + self%amp(i) * self%omega(i) * cos(self%omega(i) * t + self%phase(i))
    end do
  end subroutine rate

  !> First table corner strictly after t (huge if none): steps end there exactly, because
  !> RK4 is exact for polynomial forcing only between corners.
  pure function next_breakpoint(self, t) result(t_next)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp) :: t_next
    integer :: i, k
    t_next = huge(1.0_wp)
    do i = 1, size(self%has_table)
      if (.not. self%has_table(i)) cycle
      k = segment(self%table(i)%t, t) + 1
      if (k <= size(self%table(i)%t)) t_next = min(t_next, self%table(i)%t(k))
    end do
  end function next_breakpoint

  !> True when the forcing is polynomial between breakpoints (no sine term).
  pure logical function is_polynomial(self)
    class(forcing_type), intent(in) :: self
    is_polynomial = .not. any(self%has_sine)
  end function is_polynomial

  pure function table_value(table, t) result(f)
    type(table_type), intent(in) :: table
    real(wp), intent(in) :: t
    real(wp) :: f, s
    integer :: k, n
    n = size(table%t)
    k = segment(table%t, t)
    if (k < 1) then
      f = table%f(1)
    else if (k >= n) then
      f = table%f(n)
    else
      s = (t - table%t(k)) / (table%t(k + 1) - table%t(k))
      f = table%f(k) + s * (table%f(k + 1) - table%f(k))
    end if
  end function table_value

  !> Index k with times(k) <= t < times(k+1); 0 before the first time, n at or after the last.
  pure integer function segment(times, t) result(k)
    real(wp), contiguous, intent(in) :: times(:)
    real(wp), intent(in) :: t
    integer :: lo, hi, mid
    lo = 0
    hi = size(times) + 1
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (times(mid) <= t) then
        lo = mid
      else
        hi = mid
      end if
    end do
    k = lo
  end function segment
end module impact1d_forcing
