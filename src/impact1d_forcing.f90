!> External forces f_i(t) = constant + table(t) + amp*sin(omega*t + phase) + the body's &sine
!> records' sum_j amp_j sin(omega_j t + phase_j), each term present only when the scene names
!> it, so an absent term costs nothing in the stepping loop.
module impact1d_forcing
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: table_type, forcing_type, angular_frequency, table_value, table_slope, segment

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
    !> The &sine records, by body (record order within a body): body i's are sine_start(i)
    !> to sine_start(i + 1) - 1 of sine_amp, sine_omega, sine_phase (set_sines).
    integer, allocatable :: sine_start(:)       !< (N + 1) body i's first &sine term
    real(wp), allocatable :: sine_amp(:), sine_omega(:), sine_phase(:)   !< (ns) N, rad/s, rad
    integer :: n_sines = 0                      !< ns (0: the loops over them are skipped whole)
    !> add_sines, once set_sines has run (called through a pointer: see add_sines)
    procedure(add_sines), pointer, nopass :: sine_terms => null()
    logical :: varies = .false.                 !< some body has a table or a sine (set_varies)
    real(wp) :: fastest = 0.0_wp                !< the largest omega of any sine (0: none; set_varies)
  contains
    procedure :: allocate_bodies
    procedure :: set_sines
    procedure :: set_varies
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
      self%omega(n), self%phase(n), self%sine_start(n + 1), self%sine_amp(0), self%sine_omega(0), &
      self%sine_phase(0))
    self%sine_start = 1
    self%constant = 0.0_wp
    self%has_table = .false.
    self%has_sine = .false.
    self%amp = 0.0_wp
    self%omega = 0.0_wp
    self%phase = 0.0_wp
  end subroutine allocate_bodies

  !> The angular frequency 2 pi / period of a sine (its own and the &sine records' alike,
  !> so that the same period gives the same bits).
  elemental real(wp) function angular_frequency(period) result(omega)
    real(wp), intent(in) :: period
    omega = 2.0_wp * acos(-1.0_wp) / period
  end function angular_frequency

  !> The &sine records (body(j), amp(j), period(j), phase(j), in record order), grouped by
  !> body with each body's in record order (the order of its sum).
  pure subroutine set_sines(self, body, amp, period, phase)
    class(forcing_type), intent(inout) :: self
    integer, intent(in) :: body(:)
    real(wp), intent(in) :: amp(:), period(:), phase(:)
    integer :: i, j, k, next(size(self%constant))
    self%sine_start(1) = 1
    do i = 1, size(self%constant)
      self%sine_start(i + 1) = self%sine_start(i) + count(body == i)
    end do
    next = self%sine_start(:size(self%constant))
    self%n_sines = size(body)
    self%sine_terms => add_sines
    deallocate(self%sine_amp, self%sine_omega, self%sine_phase)
    allocate(self%sine_amp(size(body)), self%sine_omega(size(body)), self%sine_phase(size(body)))
    do j = 1, size(body)
      k = next(body(j))
      next(body(j)) = k + 1
      self%sine_amp(k) = amp(j)
      self%sine_omega(k) = angular_frequency(period(j))
      self%sine_phase(k) = phase(j)
    end do
  end subroutine set_sines

  !> varies: whether the forces change with time, and the fastest sine (once the terms are
  !> set).
  pure subroutine set_varies(self)
    class(forcing_type), intent(inout) :: self
    self%varies = any(self%has_table) .or. any(self%has_sine) .or. self%n_sines > 0
    self%fastest = max(maxval(self%omega, mask=self%has_sine, dim=1), maxval(self%sine_omega, dim=1), 0.0_wp)
  end subroutine set_varies

  !> fi += body i's table, sine and &sine terms at t (in that order: the order of the sums;
  !> the &sine terms in record order).
  pure subroutine add_body_varying(self, i, t, fi)
    class(forcing_type), intent(in) :: self
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: fi
    if (self%n_sines > 0) then
      call self%sine_terms(self, i, t, fi)     ! (all of them: see add_sines)
      return
    end if
    if (self%has_table(i)) fi = fi + table_value(self%table(i), t)
    if (self%has_sine(i)) fi = fi + own_sine(self, i, t)
  end subroutine add_body_varying

  !> Body i's own sine at t (when has_sine(i)).
  pure real(wp) function own_sine(self, i, t)
    type(forcing_type), intent(in) :: self
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    own_sine = self%amp(i) * sin(self%omega(i) * t + self%phase(i))
  end function own_sine

  !> add_body_varying in a scene with &sine records: fi += body i's table, own sine and
  !> &sine terms at t, in that order (the records in record order). Apart, and called
  !> through a pointer as add_body_varying's first act, so that gfortran can neither inline
  !> it (gfortran 12 has no noinline attribute) nor let its loop change how a scene without
  !> records runs: with the loop inside add_body_varying every call saved more registers,
  !> 3% more instructions in a sine scene without records; as a tail call it costs three.
  !> Not vectorised: gfortran would take two sines at once from glibc's vector library,
  !> whose bits differ from sin's by up to 4 ulps.
  pure subroutine add_sines(self, i, t, fi)
    type(forcing_type), intent(in) :: self
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: fi
    integer :: k
    if (self%has_table(i)) fi = fi + table_value(self%table(i), t)
    if (self%has_sine(i)) fi = fi + own_sine(self, i, t)
    !GCC$ novector
    do k = self%sine_start(i), self%sine_start(i + 1) - 1
      fi = fi + self%sine_amp(k) * sin(self%sine_omega(k) * t + self%sine_phase(k))
    end do
  end subroutine add_sines

  !> Forces on all N bodies at time t (N-long); each body's terms in add_body_varying's order.
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

  !> Right derivative df/dt at t (N-long): tells which way a force that is exactly at a
  !> bound will go.
  pure subroutine rate(self, t, df)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp), intent(out) :: df(:)
    integer :: i, k
    df = 0.0_wp
    do i = 1, size(self%constant)
      if (self%has_table(i)) df(i) = table_slope(self%table(i), segment(self%table(i)%t, t))
      if (self%has_sine(i)) df(i) = df(i) + self%amp(i) * self%omega(i) * cos(self%omega(i) * t + self%phase(i))
      if (self%n_sines == 0) cycle
      !GCC$ novector      ! (glibc's vector cos: see add_sines)
      do k = self%sine_start(i), self%sine_start(i + 1) - 1
        df(i) = df(i) + self%sine_amp(k) * self%sine_omega(k) * cos(self%sine_omega(k) * t + self%sine_phase(k))
      end do
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

  !> True when the forcing is polynomial between breakpoints (no sine term, no &sine).
  pure logical function is_polynomial(self)
    class(forcing_type), intent(in) :: self
    is_polynomial = .not. (any(self%has_sine) .or. self%n_sines > 0)
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

  !> The slope of a table's segment k (segment's numbering): 0 before the first time and at
  !> or after the last (held there).
  pure real(wp) function table_slope(table, k) result(slope)
    type(table_type), intent(in) :: table
    integer, intent(in) :: k
    slope = 0.0_wp
    if (k >= 1 .and. k < size(table%t)) slope = (table%f(k + 1) - table%f(k)) / (table%t(k + 1) - table%t(k))
  end function table_slope

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
