!> Linear springs and viscous dampers (docs/method.md, "Springs and dampers"): elements
!> between two ends, a body or the ground, each pulling its ends together with tension
!> k ((x_b - x_a) - rest) + c (v_b - v_a). A scene that names none has springs%present
!> false and the solver never calls this module.
!> A kernel of the pair, in lanes (impact1d_lanes): the model's element records
!> (scene_type's element_*) as the kernel sees them, their ends as lanes (0: the ground, at
!> x = 0). Sums run over the elements in record order from +0 (k1, k2, k12 for the tutorial's
!> scenes: docs/nbody-plan.md B5), which gives today's per-body forces up to the sign of a
!> zero that every consumer discards.
module impact1d_springs
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes
  implicit none
  private
  public :: springs_type, pair_elements, assemble, rate_bound

  !> Elements a unit of two bodies can have: the tutorial's three (each body to the ground,
  !> and between them) and room for more records on the pair (issue 19, stage 3).
  integer, parameter :: pair_elements = 8

  type :: springs_type
    logical :: present = .false.                  !< any stiffness or damping named
    !> The scene names a stiffness / a damping (its output has the PE / damping_loss column).
    logical :: has_spring = .false., has_damper = .false.
    integer :: n = 0                              !< elements (<= pair_elements)
    integer :: body(2, pair_elements) = 0         !< ends a, b as lanes; 0 = the ground
    !> (max_lanes, pair_elements) each element's coefficients on the lanes: -1 on end a, +1 on
    !> end b (set_normals)
    real(wp) :: normal(max_lanes, pair_elements) = 0.0_wp
    real(wp) :: k(pair_elements) = 0.0_wp         !< stiffness, N/m
    real(wp) :: rest(pair_elements) = 0.0_wp      !< rest length of x_b - x_a, m
    real(wp) :: c(pair_elements) = 0.0_wp         !< damping, N s/m
    !> An upper bound of the fastest rate in the motion (rad/s), set once (set_frequency).
    real(wp) :: omega = 0.0_wp
  contains
    procedure :: add_force
    procedure :: add_force_rate
    procedure :: potential
    procedure :: damping_power
    procedure :: set_frequency
    procedure :: linear_part
    procedure :: set_normals
  end type springs_type

contains

  !> Element j's elongation for positions x + dx (lanes): dx carries the low parts of
  !> compensated positions (and a stage's displacement), added after the large terms cancel.
  !> On its lane coefficients (normal: -1 on end a, +1 on end b, 0 on the ground or an idle
  !> lane), x_b - x_a = n . x exactly; a ground element's (x_b + 0) - rest is x_b - rest up
  !> to the sign of a zero.
  pure real(wp) function elongation(self, j, x, dx) result(e)
    class(springs_type), intent(in) :: self
    integer, intent(in) :: j
    real(wp), intent(in) :: x(max_lanes), dx(max_lanes)
    e = (along(self%normal(:, j), x) - self%rest(j)) + along(self%normal(:, j), dx)
  end function elongation

  !> n . y on the two lanes, lane 1's term first.
  pure real(wp) function along(n, y)
    real(wp), intent(in) :: n(max_lanes), y(max_lanes)
    along = n(1) * y(1) + n(2) * y(2)
  end function along

  !> f += the forces on the bodies at positions x + dx and velocities v: each element pulls
  !> its ends together with its tension t (+t on end a, -t on end b), each body's pulls summed
  !> from +0 in record order and then added to f. In lanes, with no index per end: this is
  !> the spring step's inner loop (five calls a step), and on ends looked up by index it took
  !> 17% longer (stores and loads through memory).
  pure subroutine add_force(self, x, dx, v, f)
    class(springs_type), intent(in) :: self
    real(wp), dimension(max_lanes), intent(in) :: x, dx, v
    real(wp), intent(inout) :: f(max_lanes)
    real(wp) :: pulls(max_lanes), tension
    integer :: j
    pulls = 0.0_wp
    do j = 1, self%n
      tension = self%k(j) * elongation(self, j, x, dx) + self%c(j) * along(self%normal(:, j), v)
      pulls = pulls - self%normal(:, j) * tension
    end do
    f = f + pulls
  end subroutine add_force

  !> df += the rate of the spring forces at velocities v (the dampers' part needs the
  !> accelerations and is left out: it only tells which way a force exactly at a bound goes).
  pure subroutine add_force_rate(self, v, df)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(max_lanes)
    real(wp), intent(inout) :: df(max_lanes)
    real(wp) :: pulls(max_lanes)
    integer :: j
    pulls = 0.0_wp
    do j = 1, self%n
      pulls = pulls - self%normal(:, j) * (self%k(j) * along(self%normal(:, j), v))
    end do
    df = df + pulls
  end subroutine add_force_rate

  !> Potential energy stored in the springs at positions x + dx.
  pure real(wp) function potential(self, x, dx)
    class(springs_type), intent(in) :: self
    real(wp), dimension(max_lanes), intent(in) :: x, dx
    integer :: j
    potential = 0.0_wp
    do j = 1, self%n
      potential = potential + self%k(j) * elongation(self, j, x, dx)**2
    end do
    potential = 0.5_wp * potential
  end function potential

  !> Power the dampers dissipate at velocities v.
  pure real(wp) function damping_power(self, v)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(max_lanes)
    integer :: j
    damping_power = 0.0_wp
    do j = 1, self%n
      damping_power = damping_power + self%c(j) * along(self%normal(:, j), v)**2
    end do
  end function damping_power

  !> omega: the stiffest natural frequency and the fastest damping rate over the lightest
  !> mass (min_mass): an element between bodies counts twice (it pulls on both). Steps
  !> sample the mode's conditions at least 16 times per 2 pi of it.
  pure subroutine set_frequency(self, min_mass)
    class(springs_type), intent(inout) :: self
    real(wp), intent(in) :: min_mass
    self%omega = rate_bound(self%body(:, :self%n), self%k(:self%n), self%c(:self%n), min_mass)
  end subroutine set_frequency

  !> The stiffest natural frequency and fastest damping rate of elements with ends body and
  !> coefficients k, c over the lightest mass (set_frequency's bound, for any elements).
  pure real(wp) function rate_bound(body, k, c, min_mass) result(omega)
    integer, intent(in) :: body(:, :)
    real(wp), intent(in) :: k(:), c(:), min_mass
    real(wp) :: stiffness, damping, weight
    integer :: j
    stiffness = 0.0_wp
    damping = 0.0_wp
    do j = 1, size(k)
      weight = merge(1.0_wp, 2.0_wp, body(1, j) == 0)
      stiffness = stiffness + weight * k(j)
      damping = damping + weight * c(j)
    end do
    omega = sqrt(stiffness / min_mass) + damping / min_mass
  end function rate_bound

  !> The elements' lane coefficients from their ends (body).
  pure subroutine set_normals(self)
    class(springs_type), intent(inout) :: self
    integer :: j
    self%normal = 0.0_wp
    do j = 1, self%n
      if (self%body(1, j) > 0) self%normal(self%body(1, j), j) = -1.0_wp
      self%normal(self%body(2, j), j) = 1.0_wp
    end do
  end subroutine set_normals

  !> Stiffness and damping matrices (K, C in M x'' + C x' + K x = f) of n bodies.
  pure subroutine linear_part(self, n, k, c)
    class(springs_type), intent(in) :: self
    integer, intent(in) :: n
    real(wp), intent(out) :: k(n, n), c(n, n)
    call assemble(self%body(:, :self%n), self%k(:self%n), k)
    call assemble(self%body(:, :self%n), self%c(:self%n), c)
  end subroutine linear_part

  !> The matrix of the elements' coefficients: each adds its coefficient to its bodies'
  !> diagonal entries and takes it from their shared off-diagonal ones, in record order.
  !> (An off-diagonal entry is set, not summed from +0: a link of coefficient 0 gives -0 there,
  !> as the matrix written out for the tutorial's elements did.)
  !> Elements given by their ends body(:, j) (0 the ground) and coefficients (the N-body
  !> scenes' element records, or the pair's).
  pure subroutine assemble(body, coefficient, matrix)
    integer, intent(in) :: body(:, :)
    real(wp), intent(in) :: coefficient(:)
    real(wp), intent(out) :: matrix(:, :)
    integer :: j
    logical :: coupled(size(matrix, 1), size(matrix, 1))
    matrix = 0.0_wp
    coupled = .false.
    do j = 1, size(coefficient)
      associate (a => body(1, j), b => body(2, j))
        matrix(b, b) = matrix(b, b) + coefficient(j)
        if (a == 0) cycle
        matrix(a, a) = matrix(a, a) + coefficient(j)
        if (coupled(a, b)) then
          matrix(a, b) = matrix(b, a) - coefficient(j)
        else
          matrix(a, b) = -coefficient(j)
        end if
        matrix(b, a) = matrix(a, b)
        coupled(a, b) = .true.
        coupled(b, a) = .true.
      end associate
    end do
  end subroutine assemble
end module impact1d_springs
